"""Random scenes whose only way from start to goal is a narrow passage: seeded, reproducible.

Three kinds, each placed across the swing of ``theta1`` between start and goal (``docs/robot.md``:
the arm is a 0.05 m beam at height ``z_c = 0.25 + d2`` whose flange, at radius
``0.30 + d3``, carries a tool that hangs 0.15 m down):

- ``beam``: a crate on the floor and a beam above it, both spanning the arm's radial range
  and the beam reaching above the robot: the arm passes between them, in a height band a few
  centimetres wider than the arm and tool need with the margin on both sides.
- ``window``: a wall across the swing, from beside the column beyond the reach and from the
  floor above the robot, with a window next to the column: the arm passes through it
  retracted (``d3`` small) and at the window's height.
- ``pillars``: the goal lies between two tall pillars: the arm must swing in retracted, then
  extend between them (the gap is a few centimetres wider than the arm with the margin).

The "play" (how much wider the passage is than the robot needs) is drawn from
:data:`PLAY_RANGE_M`. Start and goal are drawn as in :mod:`planning.io.scene_generator` and
kept ``margin + 0.02 m`` from every obstacle. Nothing guarantees that the passage can be
traversed within the joint ranges: that is for the planners to find out.
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np

import cpr_kin as ck
from planning.errors import PlanningError
from planning.pipeline.scene import Scene
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target

Kind = Literal["beam", "window", "pillars"]
KINDS: tuple[Kind, ...] = ("beam", "window", "pillars")
PLAY_RANGE_M = (0.03, 0.08)
"""How much wider than the robot's cross-section with the margin a passage is [m]."""
ARM_ABOVE_AXIS_M = 0.025
"""Half the arm beam's height: its top above the arm axis [m]."""
TOOL_BELOW_AXIS_M = 0.175
"""The tool's lowest point below the arm axis, with its tip's rounding [m]."""
MAX_ATTEMPTS = 1000
"""Draws of start, goal and passage before :func:`narrow_scene` gives up."""
TOP_M = 1.3
"""Height of walls and pillars: above anything the robot reaches [m]."""


def _radial_box(
    theta: float, radii: tuple[float, float], heights: tuple[float, float], width: float, name: str
) -> ck.Obstacle:
    """A box spanning ``radii`` and ``heights`` [m] along the ray at ``theta``, ``width`` across it."""
    middle = 0.5 * (radii[0] + radii[1])
    return ck.Obstacle.box(
        (radii[1] - radii[0], width, heights[1] - heights[0]),
        (middle * math.cos(theta), middle * math.sin(theta), 0.5 * (heights[0] + heights[1])),
        (0.0, 0.0, theta),
        name=name,
    )


def _band(rng: np.random.Generator, margin_m: float) -> tuple[float, float]:
    """A height band ``(low, high)`` [m] the arm and tool fit through at one arm height."""
    axis = rng.uniform(0.4, 0.7)  # the arm axis height while passing
    play = rng.uniform(*PLAY_RANGE_M)
    return axis - TOOL_BELOW_AXIS_M - margin_m - play / 2, axis + ARM_ABOVE_AXIS_M + margin_m + play / 2


def passage(
    kind: Kind, rng: np.random.Generator, theta: float, goal_radius: float, margin_m: float
) -> list[ck.Obstacle]:
    """The obstacles of one passage of ``kind`` at angle ``theta`` [rad] (pillars: around the goal)."""
    if kind == "beam":
        low, high = _band(rng, margin_m)
        width = rng.uniform(0.1, 0.25)
        return [
            _radial_box(theta, (0.35, 0.95), (0.0, low), width, "crate"),
            _radial_box(theta, (0.25, 0.95), (high, TOP_M), width, "beam"),
        ]
    if kind == "window":
        low, high = _band(rng, margin_m)
        width = rng.uniform(0.05, 0.1)
        outer = (
            0.30 + rng.uniform(0.05, 0.3) + 0.02 + margin_m + rng.uniform(*PLAY_RANGE_M)
        )  # flange + tool half
        return [
            _radial_box(theta, (0.25, 1.0), (0.0, low), width, "wall_below"),
            _radial_box(theta, (0.25, 1.0), (high, TOP_M), width, "wall_above"),
            _radial_box(theta, (outer, 1.0), (low, high), width, "wall_beside"),
        ]
    pillar = rng.uniform(0.03, 0.06)
    half_gap = 0.025 + margin_m + 0.02 + rng.uniform(*PLAY_RANGE_M) / 2  # arm half-width, margin, clear goal
    offset = (half_gap + pillar) / goal_radius
    return [
        ck.Obstacle.cylinder(
            pillar,
            TOP_M,
            (
                goal_radius * math.cos(theta + side * offset),
                goal_radius * math.sin(theta + side * offset),
                TOP_M / 2,
            ),
            name=f"pillar_{index}",
        )
        for index, side in enumerate((-1.0, 1.0))
    ]


def narrow_scene(
    rng: np.random.Generator,
    robot: ck.Robot,
    kind: Kind,
    name: str = "narrow",
    margin_m: float = 0.05,
    planner: PlannerSettings | None = None,
) -> Scene:
    """One random scene of ``kind`` (module docstring)."""
    if kind not in KINDS:
        raise PlanningError(f"kind = {kind!r}; allowed: {', '.join(map(repr, KINDS))}")
    for _ in range(MAX_ATTEMPTS):
        theta_start = rng.uniform(-2.5, 2.5)
        theta_goal = float(np.clip(theta_start + rng.choice([-1, 1]) * rng.uniform(0.9, 2.6), -2.7, 2.7))
        if abs(theta_goal - theta_start) < 0.9:
            continue
        radius_goal = rng.uniform(0.55, 0.78) if kind == "pillars" else rng.uniform(0.4, 0.78)
        start = Target(tcp=(*_polar(theta_start, rng.uniform(0.4, 0.78)), rng.uniform(0.12, 0.65)))
        goal = Target(tcp=(*_polar(theta_goal, radius_goal), rng.uniform(0.12, 0.65)))
        theta = (
            theta_goal
            if kind == "pillars"
            else theta_start + rng.uniform(0.35, 0.65) * (theta_goal - theta_start)
        )
        obstacles = passage(kind, rng, theta, radius_goal, margin_m)
        ends = np.array([start.configuration(robot), goal.configuration(robot)])
        clearance = ck.CollisionWorld(robot, obstacles).clearance_batch(ends).min_clearance_m
        if clearance.min() >= margin_m + 0.02:
            return Scene(
                name=name,
                start=start,
                goal=goal,
                obstacles=tuple(obstacles),
                safety_margin=margin_m,
                planner=planner or PlannerSettings(),
            )
    raise PlanningError(  # pragma: no cover - about one draw in two is kept
        f"no {kind} scene with start and goal {margin_m + 0.02:g} m clear in {MAX_ATTEMPTS} draws"
    )


def _polar(theta: float, radius: float) -> tuple[float, float]:
    return radius * math.cos(theta), radius * math.sin(theta)
