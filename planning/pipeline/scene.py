"""What to plan: the robot, the obstacles, the start and goal, the margin and the settings.

A :class:`Scene` is the pipeline's input (``scene.yaml`` is its file form,
:mod:`planning.io.scene_file`). Its defaults live here once: :data:`DEFAULT_SAFETY_MARGIN_M`,
:data:`DEFAULT_SPLINE`, and the planner's in :mod:`planning.pipeline.settings`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.names import shown, unprintable
from cpr_kin.kinematics.dynamics import TORQUE_SCALE_RANGE
from planning.curves.spline_settings import SplineSettings
from planning.errors import PlanningError
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target
from planning.validation import instance_of, number_in

FloatArray = NDArray[np.float64]

DEFAULT_SAFETY_MARGIN_M = 0.1
"""Clearance every robot geometry keeps from every obstacle unless a scene says otherwise [m]
(the paper's value)."""

DEFAULT_SELF_MARGIN_M = 0.01
"""Clearance the robot keeps from itself unless a scene says otherwise [m], between the link
pairs its SRDF leaves checked (the CPR has none)."""

DEFAULT_SPLINE = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
"""The spline of a scene unless it says otherwise: the paper's weights, but at rest at both
ends, which a real robot needs (the paper case itself uses natural ends)."""

MAX_SAFETY_MARGIN_M = 1.0
"""Largest safety margin [m]: about an arm's whole reach (a Panda's 0.86 m, a UR10's 1.3 m)."""
DURATION_RANGE_S = (0.01, 600.0)
"""Allowed fixed durations [s]."""
MAX_IPO_SAMPLES = 100_000
"""Most IPO samples of a fixed duration, ``duration / ipo``: the fitness samples every
candidate's path at each (about 100,000 x 150 columns x 8 bytes = 120 MB per array)."""
MAX_OBSTACLES = 500
"""Most obstacles in a scene (each adds six robot-obstacle pairs to every check)."""
SPLINE_P_RANGE = (1e-6, 1e12)
"""Allowed finite node weights ``p`` of a scene's spline (``inf`` also: exact interpolation);
beyond them the banded system loses the digits that the node deviation is measured in."""
SPLINE_A_RANGE = (1e-6, 1e6)
"""Allowed non-zero velocity, acceleration and jerk weights ``a_r`` of a scene's spline."""


@dataclass(frozen=True)
class Scene:
    """A planning problem.

    Attributes:
        start: where the robot stands.
        goal: where it must go.
        obstacles: static obstacles, unique names, at most :data:`MAX_OBSTACLES`.
        safety_margin: required clearance between every robot geometry and every obstacle
            [m], at most :data:`MAX_SAFETY_MARGIN_M`.
        duration: trajectory duration [s], in :data:`DURATION_RANGE_S` and at most
            :data:`MAX_IPO_SAMPLES` IPO periods; ``None``: the fastest timing within the
            joints' velocity, acceleration and jerk limits.
        robot: the robot (:class:`cpr_kin.RobotSpec`; a URDF path becomes
            :func:`cpr_kin.robot_spec` of it); ``None``: the one given to
            :func:`~planning.pipeline.planner.plan` (a scene file without ``robot:`` reads as
            the CPR preset, :func:`planning.io.robot_entry.default_robot`).
        self_margin: required clearance between the robot's own checked link pairs [m], at
            most :data:`MAX_SAFETY_MARGIN_M`.
        allowed_collisions: link pairs allowed to touch, beyond the robot's SRDF (a MoveIt
            scene's allowed-collision matrix).
        planner: planner settings.
        spline: spline settings (default :data:`DEFAULT_SPLINE`); finite weights ``p`` in
            :data:`SPLINE_P_RANGE`, non-zero ``a_r`` in :data:`SPLINE_A_RANGE`.
        name: a name for reports.
        payload: a load the robot carries (:class:`cpr_kin.Payload`), part of its torques.
        torque_scale: share of the URDF's effort limits the torques may use, in
            :data:`cpr_kin.kinematics.dynamics.TORQUE_SCALE_RANGE`.
    """

    start: Target
    goal: Target
    obstacles: tuple[ck.Obstacle, ...] = ()
    safety_margin: float = DEFAULT_SAFETY_MARGIN_M
    duration: float | None = None
    robot: ck.RobotSpec | None = None
    self_margin: float = DEFAULT_SELF_MARGIN_M
    allowed_collisions: tuple[tuple[str, str], ...] = ()
    planner: PlannerSettings = field(default_factory=PlannerSettings)
    spline: SplineSettings = DEFAULT_SPLINE
    name: str = "scene"
    payload: ck.Payload | None = None
    torque_scale: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise PlanningError(f"scene name {shown(self.name)} must be a non-empty text")
        character = unprintable(self.name)
        if character is not None:
            raise PlanningError(
                f"scene name {shown(self.name)} holds {character}; names must be printable text"
            )
        for end in ("start", "goal"):
            instance_of(end, getattr(self, end), Target, "planning.Target (q=..., tcp=... or pose=...)")
        instance_of("planner", self.planner, PlannerSettings, "planning.PlannerSettings")
        instance_of("spline", self.spline, SplineSettings, "planning.SplineSettings")
        if self.payload is not None:
            instance_of("payload", self.payload, ck.Payload, "cpr_kin.Payload")
        for k, obstacle in enumerate(self.obstacles):
            instance_of(f"obstacles[{k}]", obstacle, ck.Obstacle, "cpr_kin.Obstacle (Obstacle.box, ...)")
        number_in("safety_margin", self.safety_margin, 0.0, MAX_SAFETY_MARGIN_M, unit="m")
        number_in("self_margin", self.self_margin, 0.0, MAX_SAFETY_MARGIN_M, unit="m")
        number_in("torque_scale", self.torque_scale, *TORQUE_SCALE_RANGE)
        if isinstance(self.robot, str | Path):
            object.__setattr__(self, "robot", ck.robot_spec(self.robot))
        object.__setattr__(
            self, "allowed_collisions", tuple((str(a), str(b)) for a, b in self.allowed_collisions)
        )
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
        if len(self.obstacles) > MAX_OBSTACLES:
            raise PlanningError(f"{len(self.obstacles)} obstacles; at most {MAX_OBSTACLES}")
        for k, p in enumerate(np.atleast_1d(self.spline.p)):
            if np.isfinite(p):
                number_in(f"spline.p[{k}]" if np.ndim(self.spline.p) else "spline.p", p, *SPLINE_P_RANGE)
        for r, a in enumerate(self.spline.a):
            if a != 0.0:
                number_in(f"spline.a[{r}]", a, *SPLINE_A_RANGE)
        if self.duration is not None:
            number_in("duration", self.duration, *DURATION_RANGE_S, unit="s")
            samples = self.duration / self.planner.ipo
            if samples > MAX_IPO_SAMPLES:
                raise PlanningError(
                    f"duration / planner.ipo = {samples:.0f} IPO samples; at most {MAX_IPO_SAMPLES}: "
                    "lengthen ipo or shorten the duration"
                )

    def robot_spec(self) -> ck.RobotSpec:
        """The robot the scene names.

        Raises:
            PlanningError: it names none, and no loaded robot was given with it.
        """
        if self.robot is None:
            raise PlanningError(
                f"scene '{self.name}' names no robot: give Scene(robot=...) (cpr_kin.cpr_spec() for the "
                "CPR, cpr_kin.robot_spec(urdf) for another arm) or the loaded robot, plan(scene, robot)"
            )
        return self.robot

    def with_planner(self, **changes: Any) -> Scene:
        """The scene with planner settings changed, by their scene-file keys (e.g. ``seed=1``).

        Raises:
            PlanningError: an unknown setting, or a value the settings refuse
                (:meth:`~planning.pipeline.settings.PlannerSettings.updated`).
        """
        return dataclasses.replace(self, planner=self.planner.updated(**changes))
