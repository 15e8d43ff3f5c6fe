"""Parameter study behind the planner's defaults: seeded, a few minutes, one run side by side.

Plans ``--scenes`` generated scenes (``--narrow`` of them narrow passages) with the defaults
and with variants of the search's settings, warm (one process, kernels and robot loaded),
and prints per variant: scenes planned, the median warm planning time, the median
evaluations, and the durations relative to the defaults' (geometric mean of the per-scene
ratios on the scenes both plan, and its spread). The variants change one thing at a time
from the defaults (:data:`planning.scene.DEFAULT_FIREFLY`, ``seeding: paths`` with
:data:`planning.seeding.PATH_ATTEMPTS`, ``refine: cma`` with
:data:`planning.search.refinement.SIGMA`, ``ACTIVE_UPDATE``, ``NEAR_BOUND`` and
``refine_stall``); the first row is the paper's search (50 fireflies, every iteration, a
random population, no refinement).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import statistics
import time
from typing import Any
from unittest import mock

import numpy as np

import cpr_kin as ck
from planning import seeding
from planning.errors import NoSolutionError
from planning.io.scene_generator import generate_scenes
from planning.planner import plan, warm_up
from planning.scene import Scene
from planning.search import refinement

PAPER_SEARCH = {"fireflies": 50, "stall_iterations": 0, "seeding": "none", "refine": "none"}
SIGMA = "refinement sigma"
"""A variant's key for the refinement's initial step (a module constant, not a scene setting)."""
ACTIVE = "active update"
"""A variant's key for the refinement's active covariance update (a module constant likewise)."""
NEAR = "near bound"
"""A variant's key for the ratio to the objective's lower bound within which the refinement's
stalls count (a module constant likewise)."""
PATHS = "path attempts"
"""A variant's key for the seeding's most RRT-Connect paths (a module constant likewise)."""
CONSTANTS: dict[str, tuple[Any, str]] = {
    SIGMA: (refinement, "SIGMA"),
    ACTIVE: (refinement, "ACTIVE_UPDATE"),
    NEAR: (refinement, "NEAR_BOUND"),
    PATHS: (seeding, "PATH_ATTEMPTS"),
}
"""Variant keys that patch a module constant: the module and the constant's name."""
VARIANTS: dict[str, dict[str, Any]] = {
    "paper's search (n = 50, no stop, no seeds)": PAPER_SEARCH,
    "defaults": {},
    "no refinement": {"refine": "none"},
    "no refinement, stall 8 (the former defaults)": {"refine": "none", "stall_iterations": 8},
    "stall 2": {"stall_iterations": 2},
    "stall 8": {"stall_iterations": 8},
    "no early stop": {"stall_iterations": 0},
    "refinement sigma 0.015": {SIGMA: 0.015},
    "refinement sigma 0.06": {SIGMA: 0.06},
    "refinement stall 6": {"refine_stall": 6},
    "refinement stall 8": {"refine_stall": 8},
    "refinement stall 20": {"refine_stall": 20},
    "refinement with the active update": {ACTIVE: True},
    "refinement stalls counted anywhere": {NEAR: float("inf")},
    "refinement stalls counted within 1.2x": {NEAR: 1.2},
    "1 path attempt": {PATHS: 1},
    "2 path attempts": {PATHS: 2},
    "5 path attempts": {PATHS: 5},
    "n = 20": {"fireflies": 20},
    "n = 50": {"fireflies": 50},
    "alpha 0.2": {"alpha": 0.2},
    "alpha 1": {"alpha": 1.0},
    "no seeds": {"seeding": "none"},
}


def run(scene: Scene, robot: ck.Robot, changes: dict[str, Any]) -> tuple[bool, float, float, int]:
    """Planned, warm wall time [s], duration [s] and evaluations of ``scene`` with ``changes``."""
    settings = {key: value for key, value in changes.items() if key not in CONSTANTS}
    changed = dataclasses.replace(scene, planner=scene.planner.updated(**settings))
    started = time.perf_counter()
    try:
        with contextlib.ExitStack() as patches:
            for key, value in changes.items():
                if key in CONSTANTS:
                    module, name = CONSTANTS[key]
                    patches.enter_context(mock.patch.object(module, name, value))
            result = plan(changed, robot)
    except NoSolutionError:
        return False, time.perf_counter() - started, float("nan"), 0
    return True, time.perf_counter() - started, result.trajectory.duration, result.optimiser.evaluations


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=int, default=30, help="generated scenes (default: 30)")
    parser.add_argument("--narrow", type=int, default=6, help="of which narrow passages (default: 6)")
    parser.add_argument("--seed", type=int, default=1, help="seed of the scene generator (default: 1)")
    args = parser.parse_args()
    robot = ck.load_cpr()
    warm_up(robot)
    scenes = generate_scenes(args.scenes, args.seed, robot, narrow=args.narrow)
    results: dict[str, list[tuple[bool, float, float, int]]] = {name: [] for name in VARIANTS}
    for scene in scenes:  # variants interleaved scene by scene: the machine's drift hits all alike
        for name, changes in VARIANTS.items():
            results[name].append(run(scene, robot, changes))
    reference = results["defaults"]
    print(f"{len(scenes)} scenes ({args.narrow} narrow passages), generator seed {args.seed}\n")
    print(f"{'variant':<44}{'planned':>9}{'time s':>9}{'evals':>8}{'duration / defaults':>24}")
    for name, outcomes in results.items():
        ratios = [
            mine[2] / ours[2] for mine, ours in zip(outcomes, reference, strict=True) if mine[0] and ours[0]
        ]
        logs = np.log(ratios)
        low, high = np.exp(np.percentile(logs, [10, 90]))
        spread = f"{np.exp(logs.mean()):.3f} ({low:.2f}-{high:.2f})"
        print(
            f"{name:<44}{sum(o[0] for o in outcomes):>5}/{len(outcomes):<3}"
            f"{statistics.median(o[1] for o in outcomes):9.3f}"
            f"{statistics.median(o[3] for o in outcomes):8.0f}{spread:>24}"
        )
    print(
        "\nduration / defaults: geometric mean of per-scene ratios (10th-90th percentile) on scenes both plan"
    )


if __name__ == "__main__":
    main()
