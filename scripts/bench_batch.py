"""Time ``cpr-plan batch`` on generated scenes, as a user runs it: a new process each time.

Writes ``--scenes`` seeded scenes (``scripts/generate_scenes.py``, ``--narrow`` of them narrow
passages) into a temporary folder, then runs ``cpr-plan batch --workers N`` on them ``--runs``
times and prints every wall time, their median and the scenes planned. Process start-up (imports, loading the
URDF, loading the compiled kernels in every worker) is part of the figure.

With ``--compare DIR`` (another checkout of the project, e.g. ``git worktree add /tmp/old
<commit>``), that checkout's code is timed too, alternating run by run with this one, so that
the machine's drift hits both alike. Target (issue 17): 100 scenes in <= 10 s on 2 cores
(issue 7's was 20 s).
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from planning.cli.arguments import COUNT, SEED, checkout, integer_at_least

TARGET_S = 10.0


def run_batch(code: Path, scenes: Path, out: Path, workers: int) -> tuple[float, float, int]:
    """One ``cpr-plan batch`` with ``code`` first on the path: wall time [s], CPU time [s], scenes planned.

    The CPU time is that of the process and its workers (user + system). On a shared machine
    it varies less than the wall time, which also counts the time other guests hold the cores.
    """
    env = {**os.environ, "PYTHONPATH": str(code)}  # and a neutral working folder: it comes first on the path
    command = [sys.executable, "-c", "import sys; from planning.cli import main; sys.exit(main())"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    started = time.perf_counter()
    done = subprocess.run(
        [*command, "batch", str(scenes), "--out", str(out), "--workers", str(workers)],
        env=env,
        cwd=scenes.parent,
        capture_output=True,
        text=True,
        check=False,
    )
    elapsed = time.perf_counter() - started
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if done.returncode not in (0, 3):  # 3: some scenes have no trajectory, which is an outcome
        raise SystemExit(f"cpr-plan batch failed with exit code {done.returncode}:\n{done.stderr}")
    with (out / "summary.csv").open() as summary:
        planned = sum(row["status"] == "ok" for row in csv.DictReader(summary))
    return elapsed, cpu, planned


def write_scenes(code: Path, folder: Path, count: int, seed: int, narrow: int) -> Path:
    """Write the generated scenes with ``code``'s own generator: same geometry, its own defaults.

    A scene file pins the planner settings of the code that wrote it, and an older checkout
    refuses keys it does not know, so each checkout plans the scenes it generates itself.
    """
    command = [sys.executable, str(code / "scripts" / "generate_scenes.py"), "--count", str(count)]
    command += ["--seed", str(seed), "--out", str(folder)]
    if narrow:
        command += ["--narrow", str(narrow)]
    env = {**os.environ, "PYTHONPATH": str(code)}
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{code}: generating the scenes failed:\n{done.stderr}")
    return folder


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=COUNT, default=100, help="generated scenes (default: 100)")
    parser.add_argument("--seed", type=SEED, default=0, help="seed of the scene generator (default: 0)")
    parser.add_argument(
        "--narrow", type=integer_at_least(0), default=0, help="of which narrow passages (default: 0)"
    )
    parser.add_argument("--workers", type=COUNT, default=2, help="worker processes (default: 2)")
    parser.add_argument("--runs", type=COUNT, default=3, help="timed runs (default: 3)")
    parser.add_argument("--compare", type=checkout, help="another checkout to time beside this one")
    args = parser.parse_args()
    here = Path(__file__).resolve().parents[1]
    codes = {"this checkout": here}
    if args.compare is not None:
        codes[f"compare ({args.compare})"] = args.compare
    with tempfile.TemporaryDirectory() as tmp:
        scene_folders = {
            name: write_scenes(code, Path(tmp) / f"scenes-{k}", args.scenes, args.seed, args.narrow)
            for k, (name, code) in enumerate(codes.items())
        }
        # one untimed run per checkout: compiles the numba kernels if this machine never has
        for name, code in codes.items():
            run_batch(code, scene_folders[name], Path(tmp) / f"warm-up-{name}", args.workers)
        times: dict[str, list[float]] = {name: [] for name in codes}
        cpu_times: dict[str, list[float]] = {name: [] for name in codes}
        planned: dict[str, int] = {}
        for run in range(args.runs):
            for k, (name, code) in enumerate(codes.items()):
                out = Path(tmp) / f"out-{k}-{run}"
                elapsed, cpu, planned[name] = run_batch(code, scene_folders[name], out, args.workers)
                times[name].append(elapsed)
                cpu_times[name].append(cpu)
                print(
                    f"run {run + 1}, {name}: {elapsed:.1f} s wall, {cpu:.1f} s CPU, "
                    f"{planned[name]}/{args.scenes} planned"
                )
    print(f"\n{args.scenes} scenes, --workers {args.workers}, {args.runs} runs each")
    for name, values in times.items():
        spread = ", ".join(f"{v:.1f}" for v in values)
        print(
            f"  {name}: median {statistics.median(values):.1f} s wall ({spread}), "
            f"{statistics.median(cpu_times[name]):.1f} s CPU, {planned[name]} planned"
        )
    if len(codes) == 2:
        mine, other = times.values()
        ratios = [a / b for a, b in zip(mine, other, strict=True)]
        mine_cpu, other_cpu = cpu_times.values()
        cpu_ratios = [a / b for a, b in zip(mine_cpu, other_cpu, strict=True)]
        print(
            f"  this / compare, median of the runs' ratios: {statistics.median(ratios):.2f} wall, "
            f"{statistics.median(cpu_ratios):.2f} CPU"
        )
    median = statistics.median(times["this checkout"])
    verdict = "met" if median <= TARGET_S else "NOT met"
    print(f"target <= {TARGET_S:.0f} s for 100 scenes on 2 cores: {median:.1f} s -> {verdict}")


if __name__ == "__main__":
    main()
