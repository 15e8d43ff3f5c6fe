"""Time ``cpr-plan plan SCENE`` as a user meets it, a new process each run, beside the start-up floor.

    python scripts/bench_startup.py [--scene examples/scenes/shelf.yaml] [--runs 15] [--compare DIR]

Each run starts the installed command's entry (``planning.cli.app.console_main``, what
``cpr-plan`` runs) with this checkout first on the path, planning the scene into a new folder,
and ``scripts/startup_floor.py`` (the libraries a plan imports, nothing of ours), one after the
other: the machine's drift hits both alike. With ``--compare DIR`` (another checkout, e.g.
``git worktree add /tmp/old <commit>``, its kernels built), that checkout's command runs too.
One untimed run of each comes first.

Prints each command's median wall and CPU time [s] (user + system, its own process) and peak
memory [MiB], each command's time over the floor's and over the other checkout's as the median
of the runs' ratios, the time above the floor, and, for the shelf, issue 70's target (<= 0.5 s).
A figure with the kernels compiled just in time (no ``make kernels``, or ``CPR_KERNELS=jit``)
is not the target's: the table says which, and says where a module compiled ahead of time was
there but the plan still imported numba, for a kernel (or argument types) the module lacks.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from planning.cli.arguments import COUNT, checkout

HERE = Path(__file__).resolve().parents[1]
TARGET_S = 0.5
"""Issue 70's new-process target for the shelf [s]."""
SHELF = HERE / "examples" / "scenes" / "shelf.yaml"
"""The scene of that target, and the default."""
ENTRY = "from planning.cli.app import console_main; console_main()"
"""What the installed ``cpr-plan`` runs."""
NUMBA_FILE = "BENCH_STARTUP_NUMBA_FILE"
"""Where the untimed run writes whether numba was imported (an environment variable's name)."""
PROBED = f"""import os, sys
def said():
    with open(os.environ["{NUMBA_FILE}"], "w") as file:
        file.write(str("numba" in sys.modules))
leave = os._exit  # the command ends so, without Python's teardown
def leaving(status):
    said()
    leave(status)
os._exit = leaving
try:
    {ENTRY}
finally:
    said()
"""
"""``ENTRY``, then whether the process imported numba, written where :data:`NUMBA_FILE` says."""


@dataclass(frozen=True)
class Run:
    """One finished process: wall and CPU time [s], peak memory [MiB]."""

    wall_s: float
    cpu_s: float
    peak_mib: float


def timed(command: list[str], code: Path, environment: dict[str, str] | None = None) -> Run:
    """``command`` run to its end with ``code`` first on the path, ``environment`` set, its output dropped.

    Raises:
        SystemExit: the command failed (the end of its standard error said).
    """
    env = {**os.environ, **(environment or {}), "PYTHONPATH": str(code)}
    with tempfile.TemporaryFile() as errors:
        started = time.perf_counter()
        child = subprocess.Popen(command, env=env, cwd=code, stdout=subprocess.DEVNULL, stderr=errors)
        _, status, usage = os.wait4(child.pid, 0)
        wall_s = time.perf_counter() - started
        child.returncode = os.waitstatus_to_exitcode(status)  # reaped here, for its own usage
        if child.returncode != 0:
            errors.seek(0)
            said = errors.read().decode(errors="replace")[-1500:]
            raise SystemExit(f"{' '.join(command[-4:])} exited {child.returncode}:\n{said}")
    return Run(wall_s, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024)


def kernels_kind(code: Path, numba_loaded: bool) -> str:
    """How ``code``'s plan ran its kernels: compiled ahead of time, or numba's (all, or where one lacked)."""
    if not kernels_ahead(code):
        return "numba"
    return "ahead of time, but numba loaded: a kernel it lacks" if numba_loaded else "ahead of time"


def kernels_ahead(code: Path) -> bool:
    """Whether ``code``'s kernels compiled ahead of time load in a new process (no numba)."""
    probe = "from cpr_kin.common.ahead import load_kernels; print(load_kernels() is not None)"
    done = subprocess.run(
        [sys.executable, "-c", probe],
        env={**os.environ, "PYTHONPATH": str(code)},
        cwd=code,
        capture_output=True,
        text=True,
        check=False,
    )
    return done.stdout.strip() == "True"


def ratio(mine: list[float], other: list[float]) -> float:
    """The median of the runs' ratios, run by run."""
    return statistics.median(a / b for a, b in zip(mine, other, strict=True))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", type=Path, default=SHELF)
    parser.add_argument("--runs", type=COUNT, default=15, help="timed runs of each command (default: 15)")
    parser.add_argument("--compare", type=checkout, help="another checkout to time beside this one")
    args = parser.parse_args()
    scene = args.scene.resolve()
    if not scene.is_file():
        raise SystemExit(f"--scene {args.scene}: no such file; give a scene file (YAML)")
    codes = {"this checkout": HERE}
    if args.compare is not None:
        codes[f"compare ({args.compare})"] = args.compare
    floor = [sys.executable, str(HERE / "scripts" / "startup_floor.py")]
    runs: dict[str, list[Run]] = {name: [] for name in [*codes, "start-up floor"]}
    numba_loaded: dict[str, bool] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for run in range(args.runs + 1):  # the first untimed, and asked whether it imported numba
            for k, (name, code) in enumerate(codes.items()):
                out = Path(tmp) / f"out-{k}-{run}"
                said = Path(tmp) / f"numba-{k}"
                entry = ENTRY if run else PROBED
                command = [sys.executable, "-c", entry, "plan", str(scene), "--out", str(out)]
                result = timed(command, code, {NUMBA_FILE: str(said)})
                if run:
                    runs[name].append(result)
                else:
                    numba_loaded[name] = said.read_text() == "True"
            result = timed(floor, HERE)
            if run:
                runs["start-up floor"].append(result)
    floor_wall = [r.wall_s for r in runs["start-up floor"]]
    floor_cpu = [r.cpu_s for r in runs["start-up floor"]]
    print(f"`cpr-plan plan {args.scene}`, new processes, {args.runs} runs each, alternated\n")
    print("| command | kernels | wall s | CPU s | peak MiB | wall / floor | CPU / floor |")
    print("|---|---|---|---|---|---|---|")
    for name, done in runs.items():
        wall, cpu = [r.wall_s for r in done], [r.cpu_s for r in done]
        kind = "-" if name not in codes else kernels_kind(codes[name], numba_loaded[name])
        print(
            f"| {name} | {kind} | {statistics.median(wall):.3f} | {statistics.median(cpu):.3f} | "
            f"{statistics.median(r.peak_mib for r in done):.0f} | {ratio(wall, floor_wall):.2f} | "
            f"{ratio(cpu, floor_cpu):.2f} |"
        )
    mine = runs["this checkout"]
    if len(codes) == 2:
        other = runs[list(codes)[1]]
        walls = ratio([r.wall_s for r in mine], [r.wall_s for r in other])
        cpus = ratio([r.cpu_s for r in mine], [r.cpu_s for r in other])
        print(f"\nthis / compare, median of the runs' ratios: {walls:.2f} wall, {cpus:.2f} CPU")
    median_s = statistics.median(r.wall_s for r in mine)
    above = statistics.median(a.wall_s - f for a, f in zip(mine, floor_wall, strict=True))
    verdict = "met" if median_s <= TARGET_S else "NOT met"
    print(f"above the floor, median of the runs' differences: {above:.3f} s")
    if scene == SHELF.resolve():
        print(f"target <= {TARGET_S} s (issue 70): {median_s:.3f} s -> {verdict}")
    else:
        shelf = SHELF.relative_to(HERE)
        print(f"issue 70's target (<= {TARGET_S} s) is the shelf's ({shelf}), not this scene's")


if __name__ == "__main__":
    main()
