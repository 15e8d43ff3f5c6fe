"""How fast hostile scene files are refused, as a user meets it: a new ``cpr-plan`` process each.

For each case (the alias bomb, deep nesting, absurd sizes, ...) prints the exit code, the
wall time of the whole process (interpreter start-up included: about 0.3 s of it) and the
first characters of the message. With ``--compare DIR`` (another checkout, e.g. the code
before the guards), runs that checkout's CLI on the same files, stopped after ``--timeout``
seconds, and prints its time beside ours. Each figure is the median of ``--runs`` runs.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from planning.cli.arguments import COUNT, SECONDS

GOOD = "start: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [-0.5, 0.45, 0.25]}\n"
CASES = {
    "alias bomb (9^9 strings, 517 bytes)": 'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
    + "".join(
        f"{n}: &{n} [*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p}]\n"
        for p, n in zip("abcdefgh", "bcdefghi", strict=True)
    )
    + GOOD,
    "nesting 100,000 deep (200 kB)": "a: " + "[" * 100_000 + "]" * 100_000 + "\n",
    "nesting 2,000 deep": "a: " + "[" * 2_000 + "]" * 2_000 + "\n",
    "duplicate key": GOOD + "obstacles: [{shape: sphere, radius: 0.1, xyz: [0, 0.6, 0.2]}]\nobstacles: []\n",
    "fitness_samples: 20000000": GOOD + "planner: {fitness_samples: 20000000}\n",
    "fireflies: 1000000000": GOOD + "planner: {fireflies: 1000000000}\n",
    "verify_step_m: 1e-12": GOOD + "planner: {verify_step_m: 1.0e-12}\n",
    "duration: 1e5": GOOD + "duration: 1.0e5\n",
    "obstacle at 1e200 m": GOOD + "obstacles: [{shape: sphere, radius: 0.1, xyz: [1.0e200, 0, 0]}]\n",
}


def run(code: Path, scene: Path, out: Path, timeout: float) -> tuple[int | None, float, str]:
    """Exit code (None: stopped at the timeout), wall time [s], first line of stderr."""
    env = {**os.environ, "PYTHONPATH": str(code)}
    command = [sys.executable, "-c", "import sys; from planning.cli import main; sys.exit(main())"]
    started = time.perf_counter()
    try:
        done = subprocess.run(
            [*command, "plan", str(scene), "--out", str(out)],
            env=env,
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=scene.parent,
        )
    except subprocess.TimeoutExpired:
        return None, timeout, "(stopped at the timeout)"
    lines = done.stderr.strip().splitlines()
    return done.returncode, time.perf_counter() - started, lines[-1] if lines else ""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", type=Path, help="another checkout to run beside this one")
    parser.add_argument("--timeout", type=SECONDS, default=20.0, help="seconds before a run is stopped")
    parser.add_argument("--runs", type=COUNT, default=3, help="runs per case (median)")
    args = parser.parse_args()
    here = Path(__file__).resolve().parents[1]
    codes = {"ours": here} | ({"compared": args.compare.resolve()} if args.compare else {})
    with tempfile.TemporaryDirectory() as tmp:
        for label, text in CASES.items():
            scene = Path(tmp) / "scene.yaml"
            scene.write_text(text)
            figures = []
            for name, code in codes.items():
                outcomes = [
                    run(code, scene, Path(tmp) / f"out-{name}", args.timeout) for _ in range(args.runs)
                ]
                seconds = statistics.median(o[1] for o in outcomes)
                exit_code, message = outcomes[-1][0], outcomes[-1][2]
                shown = f"> {args.timeout:.0f} s" if exit_code is None else f"{seconds:.2f} s"
                figures.append(f"{name}: exit {exit_code}, {shown}")
                if name == "ours":
                    note = message[:90]
            print(f"{label:38s} {' | '.join(figures)}\n{'':38s} {note}")


if __name__ == "__main__":
    main()
