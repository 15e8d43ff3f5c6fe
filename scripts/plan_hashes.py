"""Fingerprints of the planner's output: a SHA-256 per planned scene, for same-seed comparisons.

Plans, warm and in one process, the bundled scenes (seeds 0-2), the paper case (with the
planner's default search) and the shelf with each of the planner's modes (the paper's search,
the ``paper`` fitness, the ``ptp`` path, no refinement, no seeding), fixed and free durations,
a goal at the start and ``--generated`` generated scenes (a quarter of them narrow
passages), and prints the SHA-256 of each plan's ``cpr-trajectory/1`` file (without wall
times; the recorded URDF and SRDF paths replaced by their names) and one digest of them all. Run it on
two checkouts: a refactoring that means to change no result must print the same digest.
A scene with no trajectory prints the failure's class instead of a hash.

Those scenes are all the CPR's, whose links are their own collision shapes. ``--arms N`` also
plans ``N`` scenes of :func:`planning.bench.arm_scenes.blocked_scene` (seeds 0 to ``N - 1``) for
each of :data:`ARMS`, example-robot-data's arms: the UR5's concave links have exact meshes, so
its plans go to the hulls first or, where the ends clear only on the meshes, to the meshes,
paths the CPR never takes. Their hashes get a digest of their own (``arms``), so that ``all``
stays comparable with a run without them.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning import NoSolutionError, Optimizer, PlannerSettings, Scene, load_scene, plan, warm_up
from planning.bench.arm_scenes import blocked_scene
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import integer_at_least
from planning.io.bundled import bundled_scene_paths, paper_scene_path
from planning.io.scene_file import parse_scene
from planning.io.trajectory_io import trajectory_json
from planning.search import baselines

MODES: dict[str, dict[str, Any]] = {
    "paper search": {
        "fireflies": 50,
        "alpha": 1.0,
        "stall_iterations": 0,
        "seeding": "none",
        "refine": "none",
    },
    "paper fitness": {"fitness": "paper"},
    "ptp path": {"path": "ptp", "fireflies": 20, "iterations": 20},
    "no refinement": {"refine": "none"},
    "no seeding": {"seeding": "none"},
}
"""Planner-setting changes applied to the paper case, one plan each."""
ARMS = ("ur5", "panda")
"""The example-robot-data arms of ``--arms``: one with exact meshes (the UR5's), one without."""


def scenes(generated: int, robot: ck.Robot) -> Iterator[tuple[str, Scene]]:
    """``(label, scene)`` of every scene fingerprinted (with the planner's own search)."""
    for path in bundled_scene_paths():
        scene = load_scene(path)
        for seed in range(3):
            yield f"{path.stem} seed {seed}", _changed(scene, seed=seed)
    paper = load_scene(paper_scene_path())
    default_search = dataclasses.replace(paper, planner=PlannerSettings(max_node_deviation=20e-6))
    shelf = load_scene(bundled_scene_paths()[-1])
    for mode, changes in MODES.items():
        yield f"paper, {mode}", _changed(default_search, **changes)
        yield f"shelf, {mode}", _changed(shelf, **changes)
    yield "paper, free duration", dataclasses.replace(paper, duration=None)
    yield "shelf, 3 s", dataclasses.replace(shelf, duration=3.0)
    yield "paper, goal at start", dataclasses.replace(paper, goal=paper.start)
    for scene in generate_scenes(generated, seed=5, robot=robot, narrow=generated // 4):
        yield scene.name, scene


def arm_scenes(count: int) -> Iterator[tuple[str, Scene, ck.Robot]]:
    """``(label, scene, robot)`` of ``count`` blocked scenes of each of :data:`ARMS` (module docstring)."""
    for name in ARMS:
        robot = ck.load_robot(example_robot(name))
        warm_up(robot)
        for seed in range(count):
            document = blocked_scene(f"{name}_{seed}", name, robot, seed)
            yield document["name"], parse_scene(document, f"{name} seed {seed}"), robot


def _changed(scene: Scene, **changes: Any) -> Scene:
    return scene.with_planner(**changes)


def fingerprint(scene: Scene, robot: ck.Robot, optimizer: Optimizer | None = None) -> str:
    """SHA-256 of the plan's trajectory file, or the failure's class."""
    try:
        result = plan(scene, robot, optimizer=optimizer)
    except NoSolutionError as exc:
        return type(exc).__name__
    text = trajectory_json(result)
    for path in (robot.urdf_path, robot.srdf_path):  # the checkout's folder is no part of a plan
        if path is not None:
            text = text.replace(str(path), Path(path).name)
    return hashlib.sha256(text.encode()).hexdigest()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--generated", type=integer_at_least(0), default=20, help="generated scenes (default: 20)"
    )
    parser.add_argument(
        "--arms",
        type=integer_at_least(0),
        default=0,
        help="blocked scenes of each example-robot-data arm, under their own digest (default: 0)",
    )
    args = parser.parse_args()
    robot = ck.load_cpr()
    warm_up(robot)
    total = hashlib.sha256()
    for label, scene in scenes(args.generated, robot):
        digest = fingerprint(scene, robot)
        total.update(f"{label} {digest}\n".encode())
        print(f"{label:<36} {digest}", flush=True)
    shelf = load_scene(bundled_scene_paths()[-1])
    for label, optimizer in (
        ("shelf, PSO", baselines.particle_swarm()),
        ("shelf, harmony", baselines.harmony_search()),
    ):
        digest = fingerprint(shelf, robot, optimizer)
        total.update(f"{label} {digest}\n".encode())
        print(f"{label:<36} {digest}", flush=True)
    print(f"{'all':<36} {total.hexdigest()}")
    if args.arms:
        arms = hashlib.sha256()
        for label, scene, arm in arm_scenes(args.arms):
            digest = fingerprint(scene, arm)
            arms.update(f"{label} {digest}\n".encode())
            print(f"{label:<36} {digest}", flush=True)
        print(f"{'arms':<36} {arms.hexdigest()}")


if __name__ == "__main__":
    main()
