"""Our default planner against OMPL's RRT-Connect pipeline on generated scenes, narrow passages included.

Issue 17's benchmark, one run, side by side. On ``--scenes`` seeded scenes of which
``--narrow`` are narrow passages (beam, window, pillars in turn; ``scripts/generate_scenes.py
--narrow``), every scene is planned by

- ours: :func:`planning.pipeline.planner.plan` with the scene's (default) settings, warm (one process,
  kernels loaded, robot loaded; the collision world is built in the call);
- OMPL RRT-Connect + simplification + TOPP-RA (:mod:`planning.bench.ompl_rrt`), ``--budget``
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
draw, so that a figure can be told from the draw that gave it. ``--seed S1 S2 ...`` runs and
reports each generator seed in turn, then issue 33's B per seed and the median of the seeds'
B.1 medians (fresh seeds: the figure a user meets, not one seed's draw). Needs the ``bench``
extra.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

import cpr_kin as ck
from planning.bench.narrow_passages import ALL_KINDS, KINDS
from planning.bench.ompl_rrt import plan_rrt_connect
from planning.bench.ruckig_bound import free_space_bound
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SECONDS, SEED, integer_at_least
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import duration_free_scenes
from planning.io.scene_file import dump_scene
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.warming import warm_up

CLI_TARGET_S = 1.5
B1_TARGET = 1.10
"""Issue 33 B.1: our duration over Ruckig's free-space bound, median over a seed's scenes."""


class Outcome(NamedTuple):
    """One planner on one scene."""

    solved: bool
    """A certified trajectory."""
    time_s: float
    """Warm wall time [s]."""
    duration_s: float
    """The trajectory's duration [s] (``nan`` if none)."""


@dataclass(frozen=True)
class Row:
    """Both planners on one scene."""

    kind: str
    """Its class: ``regular``, a narrow passage's kind, or a bundled scene's."""
    scene: Scene
    ours: Outcome
    theirs: Outcome
    bound_s: float
    """Ruckig's jerk-limited free-space bound [s] (:func:`~planning.bench.ruckig_bound.free_space_bound`)."""


@dataclass(frozen=True)
class SeedSummary:
    """A generator seed's figures of issue 33 B."""

    seed: int
    over_bound: float
    """B.1: our duration / bound, median over the scenes we solve."""
    time_ratios: dict[str, float]
    """B.2: ours / OMPL's median warm planning time, per class."""
    overall_ratio: float
    """The same over every scene."""


def ours(scene: Scene, robot: ck.Robot) -> Outcome:
    """Success (a certified trajectory), warm wall time [s] and duration [s] of our planner."""
    started = time.perf_counter()
    try:
        result = plan(scene, robot)
    except NoSolutionError:
        return Outcome(False, time.perf_counter() - started, float("nan"))
    elapsed = time.perf_counter() - started
    return Outcome(result.verification.accepted, elapsed, result.trajectory.duration)


def theirs(scene: Scene, robot: ck.Robot, budget_s: float) -> Outcome:
    """The same for OMPL RRT-Connect + simplification + TOPP-RA."""
    started = time.perf_counter()
    result = plan_rrt_connect(scene, robot, budget_s, scene.planner.seed)
    return Outcome(result.success, time.perf_counter() - started, result.duration)


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


@dataclass(frozen=True)
class Benchmark:
    """What the command line asks (:func:`parse_arguments`)."""

    scene_sets: tuple[tuple[int, list[Scene]], ...]
    """``(generator seed, its scenes)`` in the order given (a seed given twice runs twice)."""
    budget_s: float
    """RRT-Connect's time budget [s]."""
    cli_runs: int
    """Runs of ``cpr-plan plan`` in a new process (0: none)."""


def parse_arguments(robot: ck.Robot) -> Benchmark:
    """The command line (module docstring), with each seed's scenes for ``robot``."""
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--scenes", type=COUNT, default=100, help="number of scenes (default: 100)")
    parser.add_argument(
        "--narrow", type=integer_at_least(0), default=24, help="of which narrow passages (default: 24)"
    )
    parser.add_argument(
        "--seed",
        type=SEED,
        nargs="+",
        default=[0],
        help="seed(s) of the scene generator, each its own run and report (default: 0)",
    )
    parser.add_argument(
        "--kinds",
        nargs="+",
        choices=ALL_KINDS,
        default=list(KINDS),
        help=f"the narrow passages' kinds, in turn (default: {' '.join(KINDS)}; all: {' '.join(ALL_KINDS)})",
    )
    parser.add_argument(
        "--budget", type=SECONDS, default=5.0, help="RRT-Connect's time budget [s] (default: 5)"
    )
    parser.add_argument(
        "--cli-runs",
        type=integer_at_least(0),
        default=5,
        help="runs of `cpr-plan plan` (default: 5; 0: none)",
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
    try:  # every seed's scenes, before anything runs: a bad argument is named at once
        scene_sets = tuple((seed, seed_scenes(args, seed, robot)) for seed in args.seed)
    except PlanningError as error:
        parser.error(str(error))
    return Benchmark(scene_sets, args.budget, args.cli_runs)


def seed_scenes(args: argparse.Namespace, seed: int, robot: ck.Robot) -> list[Scene]:
    """The scenes of generator ``seed`` for ``robot`` with the command line's planner settings."""
    scenes = generate_scenes(args.scenes, seed, robot, narrow=args.narrow, kinds=args.kinds)
    if args.bundled:
        scenes += duration_free_scenes()  # each its own class
    if args.refine_stall is not None:
        scenes = [scene.with_planner(refine_stall=args.refine_stall) for scene in scenes]
    if args.planner_seed is not None:
        scenes = [scene.with_planner(seed=args.planner_seed) for scene in scenes]
    return scenes


def run_scenes(scenes: list[Scene], robot: ck.Robot, budget_s: float) -> list[Row]:
    """Both planners on every scene, alternating, each line printed as it comes."""
    rows = []
    print(f"{'scene':<14}{'ours':>6}{'time s':>9}{'dur s':>8}   {'OMPL':>6}{'time s':>9}{'dur s':>8}")
    for scene in scenes:
        mine, peer = ours(scene, robot), theirs(scene, robot, budget_s)
        kind = scene.name.split("_")[0]
        bound = free_space_bound(build_problem(scene, robot))
        rows.append(Row("regular" if kind == "scene" else kind, scene, mine, peer, bound))
        print(
            f"{scene.name:<14}{'ok' if mine.solved else 'FAIL':>6}{mine.time_s:9.3f}{mine.duration_s:8.3f}   "
            f"{'ok' if peer.solved else 'FAIL':>6}{peer.time_s:9.3f}{peer.duration_s:8.3f}",
            flush=True,
        )
    return rows


def report(seed: int, rows: list[Row]) -> SeedSummary:
    """Print a seed's figures (module docstring) and return issue 33 B's."""
    print(
        "\nper class: success (ours / OMPL; target: ours >= OMPL's) and median warm planning time "
        "(a failure at the time it took; target: ratio <= 1)"
    )
    classes: dict[str, list[Row]] = defaultdict(list)
    for row in rows:
        classes[row.kind].append(row)
    ratios = {}
    for kind, members in classes.items():
        won, theirs_won = sum(r.ours.solved for r in members), sum(r.theirs.solved for r in members)
        verdict = "met" if won >= theirs_won else "NOT met"
        mine_s = statistics.median(r.ours.time_s for r in members)
        theirs_s = statistics.median(r.theirs.time_s for r in members)
        ratios[kind] = mine_s / theirs_s
        print(
            f"  {kind:<8} {won:3d} / {theirs_won:3d} of {len(members):3d}   {verdict:<8}"
            f"{mine_s:7.3f} s / {theirs_s:7.3f} s = {ratios[kind]:5.2f}"
        )
    missed = [r.scene.name for r in rows if r.theirs.solved and not r.ours.solved]
    print(f"  solved by OMPL, not by us: {', '.join(missed) if missed else 'none'}")

    our_time = statistics.median(r.ours.time_s for r in rows)
    their_time = statistics.median(r.theirs.time_s for r in rows)
    print(
        f"\nwarm planning time, median over {len(rows)} scenes: ours {our_time:.3f} s, OMPL pipeline "
        f"{their_time:.3f} s, ratio {our_time / their_time:.2f} (target <= 1)"
    )
    both = [r for r in rows if r.ours.solved and r.theirs.solved]
    if both:
        mine_d = np.median([r.ours.duration_s for r in both])
        peer_d = np.median([r.theirs.duration_s for r in both])
        bound_d = np.median([r.bound_s for r in both])
        beaten = sum(r.theirs.duration_s < r.bound_s for r in both)
        print(
            f"duration on the {len(both)} scenes both solve, median: ours {mine_d:.3f} s (jerk-limited), "
            f"OMPL + TOPP-RA {peer_d:.3f} s (jerk unbounded), ratio {mine_d / peer_d:.3f}\n"
            f"  Ruckig's jerk-limited bound there, median: {bound_d:.3f} s (ratio to OMPL + TOPP-RA "
            f"{bound_d / peer_d:.3f}); OMPL + TOPP-RA beats the bound on {beaten} of {len(both)} scenes"
        )
    over_bound: dict[str, list[float]] = defaultdict(list)
    for row in rows:
        if row.ours.solved:
            over_bound[row.kind].append(row.ours.duration_s / row.bound_s)
    every = [ratio for kind_ratios in over_bound.values() for ratio in kind_ratios]
    median = statistics.median(every) if every else float("nan")
    print(
        f"our duration / Ruckig's free-space bound (which ignores the obstacles), median: "
        f"{median:.3f} over {len(every)} scenes (target <= {B1_TARGET:.2f}); per class: "
        + ", ".join(f"{kind} {statistics.median(r):.3f}" for kind, r in over_bound.items())
    )
    return SeedSummary(seed, median, ratios, our_time / their_time)


def summarise(summaries: list[SeedSummary]) -> None:
    """Issue 33 B over several generator seeds: each seed's figures, then the median of their B.1."""
    print(
        "\nissue 33 B per generator seed: B.1 duration / bound (median), "
        "B.2 the slowest generated class's time ratio"
    )
    for summary in summaries:
        generated = {k: r for k, r in summary.time_ratios.items() if k == "regular" or k in ALL_KINDS}
        kind, ratio = max(generated.items(), key=lambda item: item[1])
        b1 = "met" if summary.over_bound <= B1_TARGET else "NOT met"
        b2 = "met" if ratio <= 1.0 else "NOT met"
        print(
            f"  seed {summary.seed:<6} B.1 {summary.over_bound:.3f} {b1:<8}"
            f"B.2 {kind} {ratio:.2f} {b2:<8}over all {summary.overall_ratio:.2f}"
        )
    medians = [summary.over_bound for summary in summaries]
    met = sum(median <= B1_TARGET for median in medians)
    print(
        f"B.1 met on {met} of {len(medians)} seeds; the median of the seeds' medians "
        f"{statistics.median(medians):.3f} (range {min(medians):.3f}-{max(medians):.3f})"
    )


def main() -> None:
    robot = ck.load_cpr()
    benchmark = parse_arguments(robot)
    first = benchmark.scene_sets[0][1][0]
    warm_up(robot)
    plan_rrt_connect(first, robot, benchmark.budget_s, 0)  # OMPL's imports and first call, untimed
    summaries = []
    for seed, scenes in benchmark.scene_sets:
        if len(benchmark.scene_sets) > 1:
            print(f"\n== generator seed {seed}")
        summaries.append(report(seed, run_scenes(scenes, robot, benchmark.budget_s)))
    if len(summaries) > 1:
        summarise(summaries)
    if benchmark.cli_runs:
        times = cli_wall_times(first, benchmark.cli_runs)
        median = statistics.median(times)
        print(
            f"`cpr-plan plan {first.name}` in a new process: median {median:.2f} s "
            f"over {len(times)} runs ({', '.join(f'{t:.2f}' for t in times)}); target <= {CLI_TARGET_S} s"
        )


if __name__ == "__main__":
    main()
