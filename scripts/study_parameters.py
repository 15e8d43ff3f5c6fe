"""Parameter study behind the planner's defaults: seeded, a few minutes, one run side by side.

    python scripts/study_parameters.py [--scenes N --narrow K --seed S] [--variants NAME ...]
    python scripts/study_parameters.py --files FILE_OR_FOLDER ... [--time-limit S] [--variants ...]
    python scripts/study_parameters.py --mbm [--robots panda ur5] [--limit N [--sample-seed S]] ...

Plans problems with the defaults and with variants of the search's settings, warm (one
process, kernels and robots loaded), the variants interleaved problem by problem (the
machine's drift hits all alike), and prints per variant: problems planned, the median, p95
and summed warm planning time [s], the median evaluations, the median duration over Ruckig's
jerk-limited bound for the straight line, and the durations relative to the defaults'
(geometric mean of the per-problem ratios on the problems both plan, and its 10th-90th
percentile); with ``--per-class``, that geometric mean per class too.

The problems: ``--scenes`` generated CPR scenes (``--narrow`` of them narrow passages,
generator seed ``--seed``; the default), or ``--files`` scene files and folders of any robot
(``generate_arm_scenes.py``'s, a user's own), or with ``--mbm`` MotionBenchMaker's problems
(the selection of ``bench_mbm.py``: ``--robots``, ``--classes``, ``--limit``,
``--sample-seed``, ``--names``; imported once, needs the ``bench`` extra). Scene files and
MotionBenchMaker problems are planned with a time limit (``--time-limit``).

Each variant (:data:`VARIANTS`, ``--variants`` picks some; the defaults always run, first)
changes one thing from the defaults: the scene-file keys
(:data:`planning.pipeline.settings.DEFAULT_FIREFLY`, ``seeding``, ``refine``,
``refine_stall``), the internal knobs of :class:`planning.pipeline.tuning.SearchTuning` (the
seeding's ``path_attempts``, the refinement's ``sigma``, ``active`` and ``near_bound``), or a
module's constant set for the variant's plans only (the timing's ``STEPS_PER_RAMP``, the
fitness's ``FIRST_PASS_STRIDE``, the last resort's ``POINTS_PER_PIECE`` and ``SHORTCUTS``). The paper's search
(50 fireflies, every iteration, a random population, no refinement) is one of them.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import math
import statistics
import sys
import tempfile
import time
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

import cpr_kin as ck
from planning.bench.problem_selection import add_selection, check_selection, selected_cases
from planning.bench.ruckig_bound import free_space_bound
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SECONDS, SEED, integer_at_least
from planning.errors import CprPlanError, NoSolutionError
from planning.io.scene_file import load_scene
from planning.outcome import classify
from planning.pipeline.planner import plan
from planning.pipeline.scene import Scene
from planning.pipeline.tuning import SearchTuning, SeedingTuning
from planning.search.refinement_settings import RefinementSettings
from planning.warming import warm_up

PAPER_SEARCH = {"fireflies": 50, "stall_iterations": 0, "seeding": "none", "refine": "none"}
REFERENCE = "defaults"


@dataclass(frozen=True)
class Variant:
    """A change from the defaults: planner settings, and module constants set while it plans.

    Attributes:
        settings: planner-setting changes (:meth:`~planning.PlannerSettings.updated`).
        constants: ``(module, name, value)`` each set for the variant's plans, then restored.
    """

    settings: dict[str, Any] = field(default_factory=dict)
    constants: tuple[tuple[str, str, Any], ...] = ()

    @contextlib.contextmanager
    def applied(self) -> Iterator[None]:
        """The constants set, for as long as the context lasts."""
        saved = []
        try:
            for module_name, name, value in self.constants:
                module = importlib.import_module(module_name)
                saved.append((module, name, getattr(module, name)))
                setattr(module, name, value)
            yield
        finally:
            for module, name, value in reversed(saved):
                setattr(module, name, value)


def refinement(**changes: Any) -> Variant:
    """The variant that sets the refinement's ``changes`` (its other knobs at their defaults)."""
    return Variant({"tuning": SearchTuning(refinement=RefinementSettings(**changes))})


def seeding(**changes: Any) -> Variant:
    """The variant that sets the seeding's ``changes`` (its other knobs at their defaults)."""
    return Variant({"tuning": SearchTuning(seeding=SeedingTuning(**changes))})


def constant(module: str, name: str, value: Any) -> Variant:
    """The variant that sets ``module.name`` to ``value`` while it plans."""
    return Variant(constants=((module, name, value),))


def timing_grid(steps: int) -> Variant:
    """The timing's moving averages on ``steps`` steps a ramp (``STEPS_PER_RAMP``)."""
    return constant("planning.curves.velocity_caps", "STEPS_PER_RAMP", steps)


def last_resort(*points: int) -> Variant:
    """The last resort's splines at ``points`` a piece, then stopping (``POINTS_PER_PIECE``)."""
    return constant("planning.pipeline.path_following", "POINTS_PER_PIECE", points)


def last_resort_shortcuts(count: int) -> Variant:
    """The last resort's path given ``count`` more random shortcuts (``SHORTCUTS``)."""
    return constant("planning.pipeline.path_following", "SHORTCUTS", count)


def first_pass(stride: int) -> Variant:
    """The fitness's first pass on every ``stride``-th sample (``FIRST_PASS_STRIDE``)."""
    return constant("planning.pipeline.objective", "FIRST_PASS_STRIDE", stride)


VARIANTS: dict[str, Variant] = {
    "paper's search (n = 50, no stop, no seeds)": Variant(PAPER_SEARCH),
    REFERENCE: Variant(),
    "no refinement": Variant({"refine": "none"}),
    "no refinement, stall 8 (the former defaults)": Variant({"refine": "none", "stall_iterations": 8}),
    "stall 2": Variant({"stall_iterations": 2}),
    "stall 8": Variant({"stall_iterations": 8}),
    "no early stop": Variant({"stall_iterations": 0}),
    "refinement sigma 0.03": refinement(sigma=0.03),
    "refinement sigma 0.06": refinement(sigma=0.06),
    "refinement stall 3": Variant({"refine_stall": 3}),
    "refinement stall 6": Variant({"refine_stall": 6}),
    "refinement stall 8": Variant({"refine_stall": 8}),
    "refinement stall 20": Variant({"refine_stall": 20}),
    "refinement without the active update": refinement(active=False),
    "refinement stalls counted anywhere": refinement(near_bound=float("inf")),
    "refinement stalls counted within 1.2x": refinement(near_bound=1.2),
    "1 path attempt": seeding(path_attempts=1),
    "2 path attempts": seeding(path_attempts=2),
    "5 path attempts": seeding(path_attempts=5),
    "n = 20": Variant({"fireflies": 20}),
    "n = 50": Variant({"fireflies": 50}),
    "alpha 0.2": Variant({"alpha": 0.2}),
    "alpha 1": Variant({"alpha": 1.0}),
    "no seeds": Variant({"seeding": "none"}),
    "fitness samples 48": Variant({"fitness_samples": 48}),
    "fitness first pass every 2nd sample": first_pass(2),
    "fitness first pass every 8th sample": first_pass(8),
    "timing grid 25 steps a ramp": timing_grid(25),
    "timing grid 50 steps a ramp": timing_grid(50),
    "timing grid 200 steps a ramp": timing_grid(200),
    "last resort: stop at every vertex": last_resort(),
    "last resort as at stop 137": Variant(  # the path as found, stopping at every vertex
        constants=(*last_resort().constants, *last_resort_shortcuts(0).constants)
    ),
    **{f"last resort: {n} more shortcuts": last_resort_shortcuts(n) for n in (0, 100, 200, 800, 1600)},
    "last resort: 2, 3, 4, 6, 8 points a piece": last_resort(2, 3, 4, 6, 8),
    "last resort: 3, 6 points a piece": last_resort(3, 6),
    "last resort: 3, 8 points a piece": last_resort(3, 8),
}
"""Each variant by its name (the module docstring)."""


class Problem(NamedTuple):
    """One problem of the study: its name, its class, the scene and the robot that plans it."""

    name: str
    group: str
    scene: Scene
    robot: ck.Robot


class Outcome(NamedTuple):
    """A variant's plan of one problem."""

    planned: bool
    time_s: float
    """Warm wall time [s]."""
    duration_s: float
    """Trajectory duration [s] (``nan`` when not planned)."""
    over_bound: float
    """Duration over Ruckig's bound for the straight line (``nan`` when not planned)."""
    evaluations: int


def run(problem: Problem, variant: Variant) -> Outcome:
    """Plan ``problem`` as ``variant`` changes it, warm."""
    changed = problem.scene.with_planner(**variant.settings)
    with variant.applied():
        started = time.perf_counter()
        try:
            result = plan(changed, problem.robot)
        except NoSolutionError:
            return Outcome(False, time.perf_counter() - started, math.nan, math.nan, 0)
        spent = time.perf_counter() - started
    duration = result.trajectory.duration
    return Outcome(
        True, spent, duration, duration / free_space_bound(result.problem), result.optimiser.evaluations
    )


def generated(args: argparse.Namespace) -> list[Problem]:
    """``args.scenes`` generated CPR scenes (the study's default problems)."""
    robot = ck.load_cpr()
    scenes = generate_scenes(args.scenes, args.seed, robot, narrow=args.narrow)
    return [Problem(s.name, s.name.rsplit("_", 1)[0], s, robot) for s in scenes]


def from_files(args: argparse.Namespace, out: Path) -> list[Problem]:
    """The scene files of ``--files``, or the MotionBenchMaker selection of ``--mbm``, with the time limit."""
    selection = argparse.Namespace(**{**vars(args), "scenes": args.files})
    problems = []
    for case in selected_cases(selection, out):
        scene = load_scene(case.path).with_planner(time_limit_s=args.time_limit)
        robot = ck.shared_robot(scene.robot_spec())  # the robot plan(scene) itself would load
        problems.append(Problem(case.path.stem, f"{case.robot} {case.group}", scene, robot))
    return problems


def report(problems: list[Problem], results: dict[str, list[Outcome]], per_class: bool) -> list[str]:
    """The study's table (module docstring), one line a variant."""
    reference = results[REFERENCE]
    lines = [
        f"{'variant':<44}{'planned':>9}{'median s':>10}{'p95 s':>8}{'summed s':>10}{'evals':>7}"
        f"{'over bound':>11}{'duration / defaults':>24}"
    ]
    for name, outcomes in results.items():
        both = [
            (k, mine, ours)
            for k, (mine, ours) in enumerate(zip(outcomes, reference, strict=True))
            if mine.planned and ours.planned
        ]
        logs = np.log([mine.duration_s / ours.duration_s for _, mine, ours in both]) if both else np.zeros(1)
        low, high = np.exp(np.percentile(logs, [10, 90]))
        times = sorted(o.time_s for o in outcomes)
        planned = [o for o in outcomes if o.planned]
        over = statistics.median(o.over_bound for o in planned) if planned else math.nan
        lines.append(
            f"{name:<44}{len(planned):>5}/{len(outcomes):<4}{statistics.median(times):10.3f}"
            f"{times[max(0, math.ceil(0.95 * len(times)) - 1)]:8.3f}{sum(times):10.2f}"
            f"{statistics.median(o.evaluations for o in outcomes):7.0f}{over:11.3f}"
            f"{f'{np.exp(logs.mean()):.4f} ({low:.2f}-{high:.2f})':>24}"
        )
        if per_class and name != REFERENCE:
            groups: dict[str, list[float]] = defaultdict(list)
            for k, mine, ours in both:
                groups[problems[k].group].append(math.log(mine.duration_s / ours.duration_s))
            lines.append(
                "    "
                + ", ".join(f"{g} {math.exp(statistics.mean(v)):.3f}" for g, v in sorted(groups.items()))
            )
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", type=COUNT, default=30, help="generated scenes (default: 30)")
    parser.add_argument(
        "--narrow", type=integer_at_least(0), default=6, help="of which narrow passages (default: 6)"
    )
    parser.add_argument("--seed", type=SEED, default=1, help="seed of the scene generator (default: 1)")
    parser.add_argument("--files", type=Path, nargs="+", help="scene files or folders instead")
    parser.add_argument("--mbm", action="store_true", help="MotionBenchMaker's problems instead")
    add_selection(parser)
    parser.add_argument(
        "--time-limit", type=SECONDS, default=10.0, help="each scene file's time_limit_s (default: 10)"
    )
    parser.add_argument(
        "--variants", nargs="+", metavar="NAME", help=f"only these besides '{REFERENCE}' (default: all)"
    )
    parser.add_argument("--per-class", action="store_true", help="durations / defaults per class too")
    args = parser.parse_args()
    check_selection(parser, args)
    if args.files and args.mbm:
        parser.error("give --files or --mbm, not both")
    unknown = sorted(set(args.variants or ()) - set(VARIANTS))
    if unknown:
        parser.error(f"--variants {unknown}: not variants of this study; its variants: {sorted(VARIANTS)}")
    for given in args.files or ():
        if not given.exists():
            parser.error(f"--files {given}: no such file or folder")
    chosen = {n: v for n, v in VARIANTS.items() if n == REFERENCE or not args.variants or n in args.variants}
    try:  # every problem and robot loaded before anything runs: a fault named in one line
        if args.files or args.mbm:
            problems = from_files(args, Path(tempfile.mkdtemp(prefix="study_parameters_")))
        else:
            problems = generated(args)
    except Exception as exc:  # bad input is named in one line (the project's one rule for it)
        outcome = classify(exc)
        if outcome.status != "invalid":
            raise
        parser.error(outcome.message)
    for robot in {id(p.robot): p.robot for p in problems}.values():
        warm_up(robot)
    results: dict[str, list[Outcome]] = {name: [] for name in chosen}
    for problem in problems:  # variants interleaved problem by problem: the machine's drift hits all alike
        for name, variant in chosen.items():
            try:
                results[name].append(run(problem, variant))
            except CprPlanError as exc:
                parser.error(f"{problem.name}: {exc}")
    source = (
        f"{len(problems)} problems"
        if args.files or args.mbm
        else f"{len(problems)} scenes ({args.narrow} narrow passages), generator seed {args.seed}"
    )
    print(f"{source}\n")
    print("\n".join(report(problems, {REFERENCE: results.pop(REFERENCE), **results}, args.per_class)))
    print(
        "\nover bound: median duration over Ruckig's bound; duration / defaults: geometric mean of "
        "per-problem ratios (10th-90th percentile) on problems both plan"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
