"""Random, feasible-looking scenes for benchmarks: seeded, reproducible.

A scene swings the TCP between two random reachable points at least 0.9 rad of ``theta1``
apart, with 1 to 5 obstacles of random shapes (box, sphere, cylinder, capsule) placed along
the swing, away from the column, and never within ``margin + 0.02 m`` of the start or the
goal. Nothing guarantees that a collision-free trajectory exists: that is for the planners
to find out.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np

import cpr_kin as ck
from planning.errors import PlanningError
from planning.pipeline.scene import Scene
from planning.pipeline.settings import MAX_SEED, PlannerSettings
from planning.pipeline.target import Target
from planning.validation import integer_in

MAX_SCENES = 100_000
"""Most scenes one call generates."""

if TYPE_CHECKING:
    from planning.bench.narrow_passages import Kind


def _tcp(theta1: float, radius: float, height: float) -> tuple[float, float, float]:
    return (radius * math.cos(theta1), radius * math.sin(theta1), height)


def _obstacle(rng: np.random.Generator, theta1: float, name: str) -> ck.Obstacle:
    shape = str(rng.choice(["box", "sphere", "cylinder", "capsule"]))
    size = rng.uniform(0.05, 0.2)
    radius = rng.uniform(0.35 + size, 0.85)
    xyz = (radius * math.cos(theta1), radius * math.sin(theta1), rng.uniform(0.05, 0.75))
    rpy = (0.0, 0.0, rng.uniform(-math.pi, math.pi))
    if shape == "box":
        return ck.Obstacle.box(rng.uniform(0.08, 0.35, 3), xyz, rpy, name=name)
    if shape == "sphere":
        return ck.Obstacle.sphere(size, xyz, name=name)
    tilt = (rng.uniform(-0.6, 0.6), rng.uniform(-0.6, 0.6), 0.0)
    make = ck.Obstacle.cylinder if shape == "cylinder" else ck.Obstacle.capsule
    return make(size * 0.6, rng.uniform(0.1, 0.5), xyz, tilt, name=name)


def random_scene(
    rng: np.random.Generator,
    robot: ck.Robot,
    name: str = "random",
    obstacles: int | None = None,
    margin_m: float = 0.05,
    planner: PlannerSettings | None = None,
) -> Scene:
    """One random scene; ``obstacles`` (1 to 5) drawn when not given."""
    count = int(rng.integers(1, 6)) if obstacles is None else obstacles
    while True:
        theta_start = rng.uniform(-2.5, 2.5)
        theta_goal = float(np.clip(theta_start + rng.choice([-1, 1]) * rng.uniform(0.9, 2.6), -2.7, 2.7))
        if abs(theta_goal - theta_start) < 0.9:
            continue
        start = Target(tcp=_tcp(theta_start, rng.uniform(0.4, 0.78), rng.uniform(0.12, 0.65)))
        goal = Target(tcp=_tcp(theta_goal, rng.uniform(0.4, 0.78), rng.uniform(0.12, 0.65)))
        ends = np.array([start.configuration(robot), goal.configuration(robot)])
        placed: list[ck.Obstacle] = []
        for _ in range(200):
            if len(placed) == count:
                break
            theta = theta_start + rng.uniform(0.15, 0.85) * (theta_goal - theta_start)
            candidate = _obstacle(rng, theta, f"obstacle_{len(placed)}")
            clearance = ck.CollisionWorld(robot, [candidate]).clearance_batch(ends).min_clearance_m
            if clearance.min() >= margin_m + 0.02:
                placed.append(candidate)
        if len(placed) == count:
            return Scene(
                name=name,
                robot=ck.robot_spec(robot.urdf_path),
                start=start,
                goal=goal,
                obstacles=tuple(placed),
                safety_margin=margin_m,
                planner=planner or PlannerSettings(),
            )


def generate_scenes(
    count: int,
    seed: int = 0,
    robot: ck.Robot | None = None,
    narrow: int = 0,
    kinds: Sequence[Kind] | None = None,
) -> list[Scene]:
    """``count`` random scenes from ``seed``; scene ``i`` plans with seed ``i``.

    The last ``narrow`` of them are narrow passages (:mod:`planning.bench.narrow_passages`),
    of ``kinds`` in turn (default: :data:`~planning.bench.narrow_passages.KINDS`), drawn from a
    stream of their own: the other scenes are the same whatever ``narrow`` and ``kinds`` are.

    Raises:
        PlanningError: ``count`` is no integer in [0, :data:`MAX_SCENES`], ``seed`` no
            non-negative integer, ``narrow`` not within [0, ``count``], or an unknown kind.
    """
    from planning.bench.narrow_passages import ALL_KINDS, KINDS, narrow_scene

    integer_in("count", count, 0, MAX_SCENES)
    integer_in("seed", seed, 0, MAX_SEED)
    if not 0 <= narrow <= count:
        raise PlanningError(f"narrow = {narrow} scenes; allowed: 0 to count = {count}")
    kinds = tuple(KINDS if kinds is None else kinds)
    unknown = [kind for kind in kinds if kind not in ALL_KINDS]
    if unknown or not kinds:
        raise PlanningError(f"kinds = {list(kinds)}; allowed: one or more of {', '.join(ALL_KINDS)}")
    robot = robot or ck.load_cpr()
    rng = np.random.default_rng(seed)
    scenes = []
    for index in range(count - narrow):
        scene = random_scene(rng, robot, name=f"scene_{index:03d}")
        scenes.append(replace(scene, planner=replace(scene.planner, seed=index)))
    narrow_rng = np.random.default_rng([seed, 1])
    for index in range(count - narrow, count):
        kind = kinds[(index - count + narrow) % len(kinds)]
        scene = narrow_scene(narrow_rng, robot, kind, name=f"{kind}_{index:03d}")
        scenes.append(replace(scene, planner=replace(scene.planner, seed=index)))
    return scenes
