"""Where a warm plan's time goes, stage by stage, per class: MotionBenchMaker problems or scene files.

    python scripts/profile_stages.py [--robots panda ur5] [--classes ...] [--limit N [--sample-seed S]]
                                     [--names ...] [--time-limit S] [--out DIR]
    python scripts/profile_stages.py --scenes FILE_OR_FOLDER ... [--time-limit S]
    ... [--planner KEY=VALUE ...]   (planner settings, as a scene's ``planner:`` block: ``iterations=0``)

Each problem is imported as ``scripts/bench_mbm.py`` imports it (``import-moveit``) and planned
warm (robot loaded, kernels compiled, one process) by :func:`planning.pipeline.planner.plan`
with the scene's settings and a time limit, as the benchmark plans it. For the run, the
functions of the pipeline that do each stage are wrapped in a timer (nothing else changes):

- ``build``: :func:`~planning.pipeline.problem.build_problem` (the ends' checks, the collision
  world, the objective);
- ``path``: the sampling planner's path (:func:`~planning.pipeline.path_seeds.followable_path`:
  RRT-Connect and its shortcuts);
- ``seeding``: the rest of the seeding (:func:`~planning.pipeline.seeding.seed_search`: the
  straight line's and the path's candidates evaluated);
- ``firefly``: the search (:func:`~planning.pipeline.search.search`) but its refinement;
- ``refine``: the CMA-ES refinement (:func:`~planning.search.refinement.refine_search`);
- ``timing``: the timings of the candidates (:func:`~planning.curves.path_timing.time_path`);
- ``verify``: the certified checks, torques and limits of each timed candidate
  (:func:`~planning.pipeline.verification.verify_trajectory`);
- ``other``: the rest of the plan (the hulls' problem, the choice's bookkeeping, the result).

A stage's time excludes the stages it calls (a path found inside the seeding is the path's),
so the stages and ``other`` add up to the plan's wall time. What the time buys across the
stages is timed too, each computation inclusively (:data:`COMPUTATIONS`: the margin tests of
obstacles and of the robot's own pairs, the near cells' first tests, the closest pairs' coal
distances, the search's torque-limited duration estimate, RNEA, the trajectories' extrema); they
overlap (the self tests hold the cells' tests, the estimate its RNEA), so their shares need not
add up. Printed per robot and class, for the robot's plans (``all``) and for its slowest 5 %
(those at or above its 95th percentile plan time: what a p95 target is made of): the
problems planned, their median plan [ms], median duration over Ruckig's jerk-limited bound
for the straight line (:func:`planning.bench.ruckig_bound.free_space_bound`: what each stage's
time buys) and median duration [s], then each stage's median [ms] and its share of the
class's summed time; the table as markdown to ``DIR/stages.md``; then each computation's
summed time [s] and share, to ``DIR/computations.md``. ``--planner`` changes the scenes'
planner settings (the keys of a scene file's ``planner:`` block, each value read as YAML):
``iterations=0 refine=none`` profiles the pipeline without its search. Every scene and robot is loaded
before anything runs: a missing or malformed file, a task (not one motion), or a robot that does
not load is named in one line. Needs the ``bench`` extra for MotionBenchMaker's problems
(downloaded once, :mod:`planning.bench.mbm`).
"""

from __future__ import annotations

import argparse
import functools
import importlib
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

import cpr_kin as ck
from planning.bench.problem_selection import add_selection, check_selection, selected_cases
from planning.bench.ruckig_bound import free_space_bound
from planning.cli.arguments import SECONDS
from planning.errors import CprPlanError
from planning.io.scene_file import load_scene
from planning.outcome import classify
from planning.pipeline.planner import plan
from planning.warming import warm_up

STAGES: dict[str, tuple[str, str]] = {
    "build": ("planning.pipeline.problem", "build_problem"),
    "path": ("planning.pipeline.path_seeds", "followable_path"),
    "seeding": ("planning.pipeline.seeding", "seed_search"),
    "firefly": ("planning.pipeline.search", "search"),
    "refine": ("planning.search.refinement", "refine_search"),
    "timing": ("planning.curves.path_timing", "time_path"),
    "verify": ("planning.pipeline.verification", "verify_trajectory"),
}
"""Each stage's function, by module and name (the module docstring)."""
COMPUTATIONS: dict[str, tuple[str, str]] = {
    "obstacle tests": ("cpr_kin.collision.world", "CollisionWorld.margin_violated"),
    "self tests": ("cpr_kin.collision.self_screen", "ScreenedSelfTest.violated"),
    "cells learned": ("cpr_kin.collision.near_cells", "NearCells._test"),
    "closest pairs": ("cpr_kin.collision.closest_pairs", "closest_pairs"),
    "torque estimate": ("planning.curves.torque_estimate", "sampled_torque_durations"),
    "RNEA": ("cpr_kin.kinematics.dynamics", "Dynamics.torques"),
    "extrema": ("planning.curves.trajectory", "Trajectory.extrema"),
}
"""Computations that cut across the stages, by module and name (``Class.method`` for a method)."""


class StageClock:
    """Exclusive wall times of the wrapped stages: a stage's time less that of the stages it calls.

    ``clock``: the time [s] (default: ``time.perf_counter``).
    """

    def __init__(self, clock: Callable[[], float] = time.perf_counter) -> None:
        self.clock = clock
        self.spent_s: dict[str, float] = defaultdict(float)
        self._children_s: list[float] = []  # per open stage: its nested stages' time so far

    def wrapped(self, stage: str, function: Callable[..., Any]) -> Callable[..., Any]:
        """``function`` whose calls are charged to ``stage``."""

        @functools.wraps(function)
        def timed(*args: Any, **kwargs: Any) -> Any:
            self._children_s.append(0.0)
            started = self.clock()
            try:
                return function(*args, **kwargs)
            finally:
                whole = self.clock() - started
                nested = self._children_s.pop()
                self.spent_s[stage] += whole - nested
                if self._children_s:
                    self._children_s[-1] += whole

        return timed

    def install(self) -> None:
        """Wrap every stage's function (:func:`install`)."""
        install(STAGES, self.wrapped)

    def lap(self) -> dict[str, float]:
        """The stages' times since the last lap [s], and reset."""
        return lap(self.spent_s, STAGES)


class ComputationClock:
    """Inclusive wall times of the wrapped computations (a call inside an open one of its own: once).

    ``clock``: the time [s] (default: ``time.perf_counter``).
    """

    def __init__(self, clock: Callable[[], float] = time.perf_counter) -> None:
        self.clock = clock
        self.spent_s: dict[str, float] = defaultdict(float)
        self._open: dict[str, int] = defaultdict(int)

    def wrapped(self, name: str, function: Callable[..., Any]) -> Callable[..., Any]:
        """``function`` whose calls are charged to ``name``, with all they call."""

        @functools.wraps(function)
        def timed(*args: Any, **kwargs: Any) -> Any:
            if self._open[name]:
                return function(*args, **kwargs)
            self._open[name] += 1
            started = self.clock()
            try:
                return function(*args, **kwargs)
            finally:
                self.spent_s[name] += self.clock() - started
                self._open[name] -= 1

        return timed

    def install(self) -> None:
        """Wrap every computation (:func:`install`)."""
        install(COMPUTATIONS, self.wrapped)

    def lap(self) -> dict[str, float]:
        """The computations' times since the last lap [s], and reset."""
        return lap(self.spent_s, COMPUTATIONS)


def install(
    functions: dict[str, tuple[str, str]], wrapped: Callable[[str, Callable[..., Any]], Callable[..., Any]]
) -> None:
    """Replace each of ``functions`` by ``wrapped(name, function)``.

    A method (``Class.method``) on its class; a function in its module and wherever a module
    imported it by name.
    """
    for name, (module_name, attribute) in functions.items():
        owner: Any = importlib.import_module(module_name)
        class_name, _, function_name = attribute.rpartition(".")
        if class_name:
            owner = getattr(owner, class_name)
        original = getattr(owner, function_name)
        timed = wrapped(name, original)
        setattr(owner, function_name, timed)
        for module in list(sys.modules.values()) if not class_name else ():
            if getattr(module, "__dict__", {}).get(function_name) is original:
                setattr(module, function_name, timed)


def lap(spent_s: dict[str, float], names: dict[str, tuple[str, str]]) -> dict[str, float]:
    """``spent_s`` [s] of each of ``names`` (0 where absent), and ``spent_s`` cleared."""
    spent = {name: spent_s.get(name, 0.0) for name in names}
    spent_s.clear()
    return spent


@dataclass(frozen=True)
class Profiled:
    """One plan's profile.

    Attributes:
        robot: the robot's name (MotionBenchMaker's, or the scene file's folder).
        group: the problem's class.
        total_s: the plan's wall time [s].
        stages: each stage's exclusive time [s] (:class:`StageClock`).
        over_bound: its trajectory's duration over Ruckig's bound for the straight line.
        duration_s: its trajectory's duration [s] (beside another checkout's where the goal
            may differ: a pose's IK solution, whose bound differs too).
        computations: each computation's inclusive time [s] (:class:`ComputationClock`).
    """

    robot: str
    group: str
    total_s: float
    stages: dict[str, float]
    over_bound: float
    duration_s: float
    computations: dict[str, float] = field(default_factory=dict)


TAIL = "slowest 5 %"
"""The group of a robot's plans at or above its 95th percentile plan time (issue 70's p95)."""


def by_class(rows: list[Profiled]) -> list[tuple[tuple[str, str], list[Profiled]]]:
    """The rows per robot and class, then per robot (``"all"``), then its :data:`TAIL`, in order.

    The tail holds a robot's plans whose time is at least its 95th percentile (NumPy's linear
    one, as ``scripts/bench_mbm.py`` gives the p95): where the time of a p95 target goes.
    """
    groups: dict[tuple[str, str], list[Profiled]] = defaultdict(list)
    for row in rows:
        for key in ((row.robot, row.group), (row.robot, "all")):
            groups[key].append(row)
    for robot_name in {row.robot for row in rows}:
        planned = groups[(robot_name, "all")]
        p95_s = float(np.percentile([row.total_s for row in planned], 95))
        groups[(robot_name, TAIL)] = [row for row in planned if row.total_s >= p95_s]
    last = {"all": 1, TAIL: 2}
    return sorted(groups.items(), key=lambda kv: (kv[0][0], last.get(kv[0][1], 0)))


def table(rows: list[Profiled]) -> list[str]:
    """Markdown rows per robot and class, then per robot (module docstring)."""
    columns = [*STAGES, "other"]
    lines = [
        "| robot | class | planned | median plan [ms] | duration / Ruckig bound (median) "
        + "| duration [s] (median) | "
        + " | ".join(f"{c} [ms] (share)" for c in columns)
        + " |",
        "|---|---|---|---|---|---|" + "---|" * len(columns),
    ]
    for (robot_name, group), planned in by_class(rows):
        summed = sum(row.total_s for row in planned)
        spent = [{**row.stages, "other": row.total_s - sum(row.stages.values())} for row in planned]
        cells = [
            f"{1000 * statistics.median(s[c] for s in spent):.1f} ({sum(s[c] for s in spent) / summed:.0%})"
            for c in columns
        ]
        median_ms = 1000 * statistics.median(row.total_s for row in planned)
        over_bound = statistics.median(row.over_bound for row in planned)
        duration_s = statistics.median(row.duration_s for row in planned)
        lines.append(
            f"| {robot_name} | {group} | {len(planned)} | {median_ms:.1f} | {over_bound:.3f} "
            f"| {duration_s:.3f} | " + " | ".join(cells) + " |"
        )
    return lines


def computations_table(rows: list[Profiled]) -> list[str]:
    """Markdown rows per robot and class, then per robot: each computation's summed time and share."""
    lines = [
        "| robot | class | planned | summed plans [s] | "
        + " | ".join(f"{name} [s] (share)" for name in COMPUTATIONS)
        + " |",
        "|---|---|---|---|" + "---|" * len(COMPUTATIONS),
    ]
    for (robot_name, group), planned in by_class(rows):
        summed = sum(row.total_s for row in planned)
        spent = [sum(row.computations.get(name, 0.0) for row in planned) for name in COMPUTATIONS]
        cells = [f"{seconds:.3f} ({seconds / summed:.0%})" for seconds in spent]
        lines.append(
            f"| {robot_name} | {group} | {len(planned)} | {summed:.3f} | " + " | ".join(cells) + " |"
        )
    return lines


def planner_setting(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` of ``--planner``: the key, and its value read as YAML (``3``: an integer)."""
    key, equals, value = text.partition("=")
    if not (key and equals and value):
        raise argparse.ArgumentTypeError(f"'{text}' is not KEY=VALUE (e.g. iterations=0)")
    try:
        return key, yaml.safe_load(value)
    except yaml.YAMLError as exc:
        first_line = str(exc).splitlines()[0]
        raise argparse.ArgumentTypeError(f"'{text}': the value is not YAML ({first_line})") from None


def main() -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    add_selection(parser)
    parser.add_argument(
        "--scenes", type=Path, nargs="+", help="scene files or folders instead of MotionBenchMaker"
    )
    parser.add_argument(
        "--time-limit", type=SECONDS, default=8.0, help="each plan's time_limit_s (default: 8)"
    )
    parser.add_argument(
        "--planner",
        type=planner_setting,
        nargs="+",
        default=[],
        metavar="KEY=VALUE",
        help="planner settings for every scene, as a scene file's planner: block (e.g. iterations=0)",
    )
    parser.add_argument(
        "--out", type=Path, help="folder of the scenes and stages.md (default: a temporary one)"
    )
    args = parser.parse_args()
    check_selection(parser, args)
    settings = dict(args.planner)
    if "time_limit_s" in settings:
        parser.error("--planner time_limit_s: give the time limit as --time-limit S")
    for given in args.scenes or ():
        if not given.exists():
            parser.error(f"--scenes {given}: no such file or folder")
    out = args.out or Path(tempfile.mkdtemp(prefix="profile_stages_"))
    robots: dict[str, ck.Robot] = {}
    try:  # every scene and robot loaded before anything runs: a fault named in one line
        loaded = [
            (c, load_scene(c.path).with_planner(**settings, time_limit_s=args.time_limit))
            for c in selected_cases(args, out)
        ]
        for _, scene in loaded:
            if str(scene.robot) not in robots:
                robots[str(scene.robot)] = scene.robot.load() if scene.robot is not None else ck.load_cpr()
    except Exception as exc:  # bad input is named in one line (the project's one rule for it)
        outcome = classify(exc)
        if outcome.status != "invalid":
            raise
        parser.error(outcome.message)
    for robot in robots.values():
        warm_up(robot)
    clock, computations = StageClock(), ComputationClock()
    clock.install()
    computations.install()
    rows = []
    for case, scene in loaded:
        clock.lap()
        computations.lap()
        started = time.perf_counter()
        try:
            result = plan(scene, robots[str(scene.robot)])
        except CprPlanError as exc:
            print(f"{case.robot} {case.path.stem}: not planned ({type(exc).__name__}), left out", flush=True)
            continue
        total_s, stages = time.perf_counter() - started, clock.lap()
        over_bound = result.trajectory.duration / free_space_bound(result.problem)
        duration_s = result.trajectory.duration
        rows.append(
            Profiled(case.robot, case.group, total_s, stages, over_bound, duration_s, computations.lap())
        )
        shown = " ".join(f"{stage} {1000 * spent:.0f}" for stage, spent in stages.items())
        print(
            f"{case.robot} {case.path.stem}: {1000 * total_s:.0f} ms ({shown}), "
            f"{over_bound:.3f} of Ruckig's bound ({duration_s:.3f} s)",
            flush=True,
        )
    lines, bought = table(rows), computations_table(rows)
    out.mkdir(parents=True, exist_ok=True)
    (out / "stages.md").write_text("\n".join(lines) + "\n")
    (out / "computations.md").write_text("\n".join(bought) + "\n")
    print("\n".join([*lines, "", *bought]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
