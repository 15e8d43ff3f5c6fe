"""Parameter study behind the planner's defaults: seeded, a few minutes, one run side by side.

Plans ``--scenes`` generated scenes (``--narrow`` of them narrow passages) with the defaults
and with variants of the search's settings, warm (one process, kernels and robot loaded),
and prints per variant: scenes planned, the median warm planning time, the median
evaluations, and the durations relative to the defaults' (geometric mean of the per-scene
ratios on the scenes both plan, and its spread). The variants change one thing at a time
from the defaults, all through the planner settings: the scene-file keys
(:data:`planning.pipeline.settings.DEFAULT_FIREFLY`, ``seeding``, ``refine``,
``refine_stall``) and the internal knobs of :class:`planning.pipeline.tuning.SearchTuning`
(the seeding's ``path_attempts``, the refinement's ``sigma``, ``active`` and
``near_bound``); the first row is the paper's search (50 fireflies, every iteration, a
random population, no refinement).
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, NamedTuple

import numpy as np

import cpr_kin as ck
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SEED, integer_at_least
from planning.errors import NoSolutionError
from planning.pipeline.planner import plan
from planning.pipeline.scene import Scene
from planning.pipeline.tuning import SearchTuning, SeedingTuning
from planning.search.refinement_settings import RefinementSettings
from planning.warming import warm_up

PAPER_SEARCH = {"fireflies": 50, "stall_iterations": 0, "seeding": "none", "refine": "none"}


def refinement(**changes: Any) -> dict[str, SearchTuning]:
    """The planner change that sets the refinement's ``changes`` (its other knobs at their defaults)."""
    return {"tuning": SearchTuning(refinement=RefinementSettings(**changes))}


def seeding(**changes: Any) -> dict[str, SearchTuning]:
    """The planner change that sets the seeding's ``changes`` (its other knobs at their defaults)."""
    return {"tuning": SearchTuning(seeding=SeedingTuning(**changes))}


VARIANTS: dict[str, dict[str, Any]] = {
    "paper's search (n = 50, no stop, no seeds)": PAPER_SEARCH,
    "defaults": {},
    "no refinement": {"refine": "none"},
    "no refinement, stall 8 (the former defaults)": {"refine": "none", "stall_iterations": 8},
    "stall 2": {"stall_iterations": 2},
    "stall 8": {"stall_iterations": 8},
    "no early stop": {"stall_iterations": 0},
    "refinement sigma 0.015": refinement(sigma=0.015),
    "refinement sigma 0.06": refinement(sigma=0.06),
    "refinement stall 6": {"refine_stall": 6},
    "refinement stall 8": {"refine_stall": 8},
    "refinement stall 20": {"refine_stall": 20},
    "refinement with the active update": refinement(active=True),
    "refinement stalls counted anywhere": refinement(near_bound=float("inf")),
    "refinement stalls counted within 1.2x": refinement(near_bound=1.2),
    "1 path attempt": seeding(path_attempts=1),
    "2 path attempts": seeding(path_attempts=2),
    "5 path attempts": seeding(path_attempts=5),
    "n = 20": {"fireflies": 20},
    "n = 50": {"fireflies": 50},
    "alpha 0.2": {"alpha": 0.2},
    "alpha 1": {"alpha": 1.0},
    "no seeds": {"seeding": "none"},
}
"""Each variant's planner-setting changes (:meth:`~planning.PlannerSettings.updated`)."""


class Outcome(NamedTuple):
    """A variant's plan of one scene."""

    planned: bool
    time_s: float
    """Warm wall time [s]."""
    duration_s: float
    """Trajectory duration [s] (``nan`` when not planned)."""
    evaluations: int


def run(scene: Scene, robot: ck.Robot, changes: dict[str, Any]) -> Outcome:
    """Plan ``scene`` with the planner-setting ``changes``, warm."""
    changed = scene.with_planner(**changes)
    started = time.perf_counter()
    try:
        result = plan(changed, robot)
    except NoSolutionError:
        return Outcome(False, time.perf_counter() - started, float("nan"), 0)
    return Outcome(
        True, time.perf_counter() - started, result.trajectory.duration, result.optimiser.evaluations
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=COUNT, default=30, help="generated scenes (default: 30)")
    parser.add_argument(
        "--narrow", type=integer_at_least(0), default=6, help="of which narrow passages (default: 6)"
    )
    parser.add_argument("--seed", type=SEED, default=1, help="seed of the scene generator (default: 1)")
    args = parser.parse_args()
    robot = ck.load_cpr()
    warm_up(robot)
    scenes = generate_scenes(args.scenes, args.seed, robot, narrow=args.narrow)
    results: dict[str, list[Outcome]] = {name: [] for name in VARIANTS}
    for scene in scenes:  # variants interleaved scene by scene: the machine's drift hits all alike
        for name, changes in VARIANTS.items():
            results[name].append(run(scene, robot, changes))
    reference = results["defaults"]
    print(f"{len(scenes)} scenes ({args.narrow} narrow passages), generator seed {args.seed}\n")
    print(f"{'variant':<44}{'planned':>9}{'time s':>9}{'evals':>8}{'duration / defaults':>24}")
    for name, outcomes in results.items():
        ratios = [
            mine.duration_s / ours.duration_s
            for mine, ours in zip(outcomes, reference, strict=True)
            if mine.planned and ours.planned
        ]
        logs = np.log(ratios)
        low, high = np.exp(np.percentile(logs, [10, 90]))
        spread = f"{np.exp(logs.mean()):.3f} ({low:.2f}-{high:.2f})"
        print(
            f"{name:<44}{sum(o.planned for o in outcomes):>5}/{len(outcomes):<3}"
            f"{statistics.median(o.time_s for o in outcomes):9.3f}"
            f"{statistics.median(o.evaluations for o in outcomes):8.0f}{spread:>24}"
        )
    print(
        "\nduration / defaults: geometric mean of per-scene ratios (10th-90th percentile) on scenes both plan"
    )


if __name__ == "__main__":
    main()
