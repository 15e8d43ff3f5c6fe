"""Our default planner against OMPL's RRT-Connect pipeline on generated scenes, narrow passages included.

Issue 17's benchmark, one run, side by side. On ``--scenes`` seeded scenes of which
``--narrow`` are narrow passages (beam, window, pillars in turn; ``scripts/generate_scenes.py
--narrow``), every scene is planned by

- ours: :func:`planning.pipeline.planner.plan` with the scene's (default) settings, warm (one process,
  kernels loaded, robot loaded; the collision world is built in the call);
- OMPL RRT-Connect + simplification + TOPP-RA (:mod:`planning.peers.ompl_rrt`), ``--budget``
  seconds for RRT-Connect, warm likewise, its trajectory verified by the same certified check;

the two alternating scene by scene, so that the machine's drift hits both alike. It prints
success per class, the scenes OMPL solves and we do not, the median warm planning time of
each and their ratio, the median duration on the scenes both solve (beside the median of
Ruckig's jerk-limited bound on them, which no jerk-limited planner's median can go below),
and, with ``--cli-runs``,
the wall time of ``cpr-plan plan`` on one scene as a user runs it (a new process each time,
kernels cached on disk). Targets (issue 17): success >= OMPL's on each class, warm time
ratio <= 1, ``cpr-plan plan`` <= 1.5 s. ``--refine-stall N`` plans ours with the planner
setting ``refine_stall: N`` (shorter trajectories for more planning time,
``docs/tuning.md``); OMPL's pipeline has no such setting. ``--bundled`` adds the bundled
scenes (the shelf, and the paper's with its duration free), as issue 33's B.1 counts them;
``--planner-seed N`` plans ours with the planner setting ``seed: N``, the search's own random
draw, so that a figure can be told from the draw that gave it. Needs the ``bench`` extra.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

import cpr_kin as ck
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import duration_free_scenes
from planning.io.narrow_passages import ALL_KINDS, KINDS
from planning.io.scene_file import dump_scene
from planning.io.scene_generator import generate_scenes
from planning.peers.ompl_rrt import plan_rrt_connect
from planning.peers.ruckig_bound import free_space_bound
from planning.pipeline.planner import plan, warm_up
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene

CLI_TARGET_S = 1.5


Outcome = tuple[bool, float, float]
"""Success, warm wall time [s] and duration [s] of one planner on one scene."""


def ours(scene: Scene, robot: ck.Robot) -> Outcome:
    """Success (a certified trajectory), warm wall time [s] and duration [s] of our planner."""
    started = time.perf_counter()
    try:
        result = plan(scene, robot)
    except NoSolutionError:
        return False, time.perf_counter() - started, float("nan")
    elapsed = time.perf_counter() - started
    return result.verification.accepted, elapsed, result.trajectory.duration


def theirs(scene: Scene, robot: ck.Robot, budget_s: float) -> Outcome:
    """The same for OMPL RRT-Connect + simplification + TOPP-RA."""
    started = time.perf_counter()
    result = plan_rrt_connect(scene, robot, budget_s, scene.planner.seed)
    return result.success, time.perf_counter() - started, result.duration


def cli_wall_times(scene: Scene, runs: int) -> list[float]:
    """Wall time of ``cpr-plan plan SCENE --out DIR`` in a new process, ``runs`` times [s]."""
    times = []
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "scene.yaml"
        dump_scene(scene, path)
        for run in range(runs):
            started = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "planning.cli", "plan", str(path), "--out", f"{folder}/out{run}"],
                check=True,
                capture_output=True,
            )
            times.append(time.perf_counter() - started)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--scenes", type=int, default=100, help="number of scenes (default: 100)")
    parser.add_argument("--narrow", type=int, default=24, help="of which narrow passages (default: 24)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the scene generator (default: 0)")
    parser.add_argument(
        "--kinds",
        nargs="+",
        choices=ALL_KINDS,
        default=list(KINDS),
        help=f"the narrow passages' kinds, in turn (default: {' '.join(KINDS)}; all: {' '.join(ALL_KINDS)})",
    )
    parser.add_argument(
        "--budget", type=float, default=5.0, help="RRT-Connect's time budget [s] (default: 5)"
    )
    parser.add_argument(
        "--cli-runs", type=int, default=5, help="runs of `cpr-plan plan` (default: 5; 0: none)"
    )
    parser.add_argument(
        "--refine-stall",
        type=int,
        default=None,
        help="our planner's refine_stall (default: the scenes' own, the planner's default)",
    )
    parser.add_argument(
        "--planner-seed",
        type=int,
        default=None,
        help="our planner's seed, its search's random draw (default: the scenes' own, 0)",
    )
    parser.add_argument(
        "--bundled",
        action="store_true",
        help="add the bundled scenes: the shelf and the paper's with its duration free (issue 33 B.1)",
    )
    args = parser.parse_args()

    robot = ck.load_cpr()
    try:
        scenes = generate_scenes(args.scenes, args.seed, robot, narrow=args.narrow, kinds=args.kinds)
        if args.bundled:
            scenes += duration_free_scenes()  # each its own class
        if args.refine_stall is not None:
            scenes = [scene.with_planner(refine_stall=args.refine_stall) for scene in scenes]
        if args.planner_seed is not None:
            scenes = [scene.with_planner(seed=args.planner_seed) for scene in scenes]
    except PlanningError as error:
        parser.error(str(error))
    warm_up(robot)
    plan_rrt_connect(scenes[0], robot, args.budget, 0)  # OMPL's imports and first call, untimed
    rows = []
    print(f"{'scene':<14}{'ours':>6}{'time s':>9}{'dur s':>8}   {'OMPL':>6}{'time s':>9}{'dur s':>8}")
    for scene in scenes:
        mine = ours(scene, robot)
        peer = theirs(scene, robot, args.budget)
        rows.append((scene.name.split("_")[0], scene.name, mine, peer))
        print(
            f"{scene.name:<14}{'ok' if mine[0] else 'FAIL':>6}{mine[1]:9.3f}{mine[2]:8.3f}   "
            f"{'ok' if peer[0] else 'FAIL':>6}{peer[1]:9.3f}{peer[2]:8.3f}",
            flush=True,
        )

    print(
        "\nper class: success (ours / OMPL; target: ours >= OMPL's) and median warm planning time "
        "(a failure at the time it took; target: ratio <= 1)"
    )
    classes: dict[str, list[tuple[Outcome, Outcome]]] = defaultdict(list)
    for kind, _, mine, peer in rows:
        classes["regular" if kind == "scene" else kind].append((mine, peer))
    for kind, outcomes in classes.items():
        won, theirs_won = sum(m[0] for m, _ in outcomes), sum(p[0] for _, p in outcomes)
        verdict = "met" if won >= theirs_won else "NOT met"
        mine_s = statistics.median(m[1] for m, _ in outcomes)
        theirs_s = statistics.median(p[1] for _, p in outcomes)
        print(
            f"  {kind:<8} {won:3d} / {theirs_won:3d} of {len(outcomes):3d}   {verdict:<8}"
            f"{mine_s:7.3f} s / {theirs_s:7.3f} s = {mine_s / theirs_s:5.2f}"
        )
    missed = [name for _, name, mine, peer in rows if peer[0] and not mine[0]]
    print(f"  solved by OMPL, not by us: {', '.join(missed) if missed else 'none'}")

    our_time = statistics.median(mine[1] for *_, mine, _ in rows)
    their_time = statistics.median(peer[1] for *_, peer in rows)
    print(
        f"\nwarm planning time, median over {len(rows)} scenes: ours {our_time:.3f} s, OMPL pipeline "
        f"{their_time:.3f} s, ratio {our_time / their_time:.2f} (target <= 1)"
    )
    both = [
        (scene, mine[2], peer[2])
        for scene, (_, _, mine, peer) in zip(scenes, rows, strict=True)
        if mine[0] and peer[0]
    ]
    if both:
        mine_d, peer_d = np.median([b[1] for b in both]), np.median([b[2] for b in both])
        bounds = [free_space_bound(build_problem(scene, robot)) for scene, *_ in both]
        bound_d = np.median(bounds)
        beaten = sum(b[2] < bound for b, bound in zip(both, bounds, strict=True))
        print(
            f"duration on the {len(both)} scenes both solve, median: ours {mine_d:.3f} s (jerk-limited), "
            f"OMPL + TOPP-RA {peer_d:.3f} s (jerk unbounded), ratio {mine_d / peer_d:.3f}\n"
            f"  Ruckig's jerk-limited bound there, median: {bound_d:.3f} s (ratio to OMPL + TOPP-RA "
            f"{bound_d / peer_d:.3f}); OMPL + TOPP-RA beats the bound on {beaten} of {len(both)} scenes"
        )
    over_bound: dict[str, list[float]] = defaultdict(list)
    for scene, (kind, _, mine, _) in zip(scenes, rows, strict=True):
        if mine[0]:
            bound = free_space_bound(build_problem(scene, robot))
            over_bound["regular" if kind == "scene" else kind].append(mine[2] / bound)
    every = [ratio for ratios in over_bound.values() for ratio in ratios]
    print(
        f"our duration / Ruckig's free-space bound (which ignores the obstacles), median: "
        f"{statistics.median(every):.3f} over {len(every)} scenes (target <= 1.10); per class: "
        + ", ".join(f"{kind} {statistics.median(r):.3f}" for kind, r in over_bound.items())
    )
    if args.cli_runs:
        times = cli_wall_times(scenes[0], args.cli_runs)
        median = statistics.median(times)
        print(
            f"`cpr-plan plan {scenes[0].name}` in a new process: median {median:.2f} s "
            f"over {len(times)} runs ({', '.join(f'{t:.2f}' for t in times)}); target <= {CLI_TARGET_S} s"
        )


if __name__ == "__main__":
    main()
