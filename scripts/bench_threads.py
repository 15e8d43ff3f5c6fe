"""Warm planning time on one thread and on two, on an idle machine and beside a busy process.

    python scripts/bench_threads.py [--robots panda ur5] [--limit 1] [--sample-seed 11] [--busy 1]
    python scripts/bench_threads.py --scenes FILE_OR_FOLDER ... [--busy 1]

Each selected MotionBenchMaker problem (or scene file) is planned warm (robot loaded, kernels compiled, one
process) by :func:`planning.pipeline.planner.plan` with ``threads`` 1 and 2 in turn (the
same trajectory either way: coal's answers do not depend on the threads), first on the
machine as it is, then again while ``--busy`` processes this script starts spin on a core
each (what a user's simulator, browser or second planner does to a plan). Prints per robot
and load the median and summed planning time of each thread count and their ratio: what
:func:`cpr_kin.collision.coal_pools.default_threads` chooses from (docs/tuning.md, Threads).
"""

from __future__ import annotations

import argparse
import multiprocessing
import statistics
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import cpr_kin as ck
from planning.bench.problem_selection import Case, add_selection, check_selection, selected_cases
from planning.cli.arguments import COUNT
from planning.io.scene_file import load_scene
from planning.pipeline.planner import plan
from planning.pipeline.scene import Scene
from planning.warming import warm_up

THREADS = (1, 2)
TIME_LIMIT_S = 20.0
"""Each plan's ``time_limit_s`` [s], as the MotionBenchMaker benchmark plans them."""


def _spin() -> None:
    """Keep a core busy until terminated."""
    while True:
        pass


@contextmanager
def busy(processes: int) -> Iterator[None]:
    """``processes`` processes spinning on a core each while the block runs."""
    spinning = [multiprocessing.Process(target=_spin, daemon=True) for _ in range(processes)]
    for process in spinning:
        process.start()
    try:
        time.sleep(0.5)  # the scheduler has placed them
        yield
    finally:
        for process in spinning:
            process.terminate()
            process.join()


def loaded(cases: list[Case]) -> list[tuple[Scene, ck.Robot]]:
    """Each case's scene with its robot, each robot loaded once and its kernels warmed."""
    scenes = [load_scene(case.path).with_planner(time_limit_s=TIME_LIMIT_S) for case in cases]
    robots = {spec: spec.load() for spec in {scene.robot_spec() for scene in scenes}}
    for robot in robots.values():
        warm_up(robot)
    return [(scene, robots[scene.robot_spec()]) for scene in scenes]


def planning_times(planned: list[tuple[Scene, ck.Robot]]) -> dict[int, list[float]]:
    """Warm planning time [s] of each scene with each thread count, alternated scene by scene."""
    times: dict[int, list[float]] = {threads: [] for threads in THREADS}
    for scene, robot in planned:
        for threads in THREADS:
            started = time.perf_counter()
            plan(scene, robot, threads=threads)
            times[threads].append(time.perf_counter() - started)
    return times


def main() -> int:
    """Print the table (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_selection(parser)
    parser.add_argument("--scenes", nargs="+", type=Path, help="scene files or folders instead")
    parser.add_argument("--busy", type=COUNT, default=1, help="spinning processes of the loaded run")
    parser.set_defaults(limit=1, sample_seed=11)
    args = parser.parse_args()
    check_selection(parser, args)
    out = Path(tempfile.mkdtemp())
    print("| robot | machine | problems | 1 thread: median (sum) [s] | 2 threads | 2 / 1 (median) |")
    print("|---|---|---|---|---|---|")
    groups: dict[str, list[Case]] = {}
    for case in selected_cases(args, out):
        groups.setdefault(case.robot, []).append(case)
    for robot_name, cases in groups.items():
        planned = loaded(cases)
        for machine, processes in (("no spinner", 0), (f"{args.busy} spinning", args.busy)):
            with busy(processes):
                times = planning_times(planned)
            one, two = (times[threads] for threads in THREADS)
            print(
                f"| {robot_name} | {machine} | {len(cases)} | {statistics.median(one):.3f} ({sum(one):.2f}) "
                f"| {statistics.median(two):.3f} ({sum(two):.2f}) "
                f"| {statistics.median(two) / statistics.median(one):.2f} |",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
