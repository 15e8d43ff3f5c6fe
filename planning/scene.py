"""What to plan: the robot, the obstacles, the start and goal, the margin and the settings.

Every default lives here once: :data:`DEFAULT_SAFETY_MARGIN_M`, :data:`DEFAULT_SPLINE` and
the fields of :class:`PlannerSettings` (with its nested
:class:`~planning.search.firefly.FireflySettings`). The scene file's schema
(:mod:`planning.io.scene_schema`) reads its defaults from them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SplineSettings
from planning.errors import PlanningError
from planning.search.firefly import FireflySettings

FloatArray = NDArray[np.float64]
Fitness = Literal["clearance", "paper"]
PathKind = Literal["spline", "ptp"]

DEFAULT_SAFETY_MARGIN_M = 0.1
"""Clearance every robot geometry keeps from every obstacle unless a scene says otherwise [m]
(the paper's value)."""

DEFAULT_SPLINE = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
"""The spline of a scene unless it says otherwise: the paper's weights, but at rest at both
ends, which a real robot needs (the paper case itself uses natural ends)."""

_FIREFLY_FIELDS = frozenset(f.name for f in dataclasses.fields(FireflySettings))


@dataclass(frozen=True)
class Target:
    """A start or goal: a TCP position (wrist angles held) or a full joint vector.

    Attributes:
        tcp: ``(x, y, z)`` of the TCP [m], solved with the analytic IK, or ``None``.
        q: ``(theta1, d2, d3, theta4, theta5)`` [rad, m], or ``None``.
        theta4: wrist roll used with ``tcp`` [rad].
        theta5: tool pitch used with ``tcp`` [rad].
    """

    tcp: tuple[float, float, float] | None = None
    q: tuple[float, ...] | None = None
    theta4: float = 0.0
    theta5: float = 0.0

    def __post_init__(self) -> None:
        if (self.tcp is None) == (self.q is None):
            raise PlanningError("a start or goal needs exactly one of 'tcp' (x, y, z) or 'q' (joint vector)")

    def configuration(self, robot: ck.Robot) -> FloatArray:
        """The joint vector [rad, m]; raises :class:`cpr_kin.CprKinError` if unreachable."""
        if self.tcp is not None:
            return ck.tcp_ik(robot, self.tcp, self.theta4, self.theta5)
        return robot.configuration(np.asarray(self.q, dtype=float))


@dataclass(frozen=True)
class PlannerSettings:
    """Settings of the waypoint planner; validated on construction.

    Attributes:
        firefly: the firefly algorithm's parameters (the paper's by default).
        waypoints: number of intermediate waypoints p. The paper: 3.
        fitness: ``"clearance"`` (feasible first, infeasible ranked by coal's violation
            depth) or ``"paper"`` (eq. 4-6).
        seed: seed of the random generator.
        path: what the fitness checks: the executed ``"spline"`` (default) or the
            paper's straight joint-space ``"ptp"`` moves.
        ipo: controller interpolation period [s] for w_sol.
        fitness_samples: configurations checked per candidate path in the fitness.
        verify_step_m: robot motion between two checks in the final verification [m];
            the fitness requires this much clearance beyond the margin.
        max_node_deviation: largest spline node deviation a candidate may have [rad or m];
            ``None`` (default): no bound. The paper case requires 20e-6.
        moving_joints: joints the waypoints move; default: theta1, d2, d3, and a wrist
            joint when start and goal differ in it.
    """

    firefly: FireflySettings = field(default_factory=FireflySettings)
    waypoints: int = 3
    fitness: Fitness = "clearance"
    seed: int = 0
    path: PathKind = "spline"
    ipo: float = 0.012
    fitness_samples: int = 64
    verify_step_m: float = 0.005
    max_node_deviation: float | None = None
    moving_joints: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.firefly, FireflySettings):
            raise PlanningError(f"firefly = {self.firefly!r} must be a FireflySettings")
        if not (isinstance(self.waypoints, int) and self.waypoints >= 1):
            raise PlanningError(f"waypoints = {self.waypoints!r} must be an integer >= 1")
        if self.fitness not in ("clearance", "paper"):
            raise PlanningError(f"fitness = {self.fitness!r}; allowed: 'clearance', 'paper'")
        if self.path not in ("spline", "ptp"):
            raise PlanningError(f"path = {self.path!r}; allowed: 'spline', 'ptp'")
        if not (isinstance(self.seed, int) and self.seed >= 0):
            raise PlanningError(f"seed = {self.seed!r} must be an integer >= 0")
        if not (math.isfinite(self.ipo) and self.ipo > 0):
            raise PlanningError(f"ipo = {self.ipo!r} s must be a finite number > 0")
        if not (isinstance(self.fitness_samples, int) and self.fitness_samples >= 2):
            raise PlanningError(f"fitness_samples = {self.fitness_samples!r} must be an integer >= 2")
        if self.max_node_deviation is not None and not (
            math.isfinite(self.max_node_deviation) and self.max_node_deviation > 0
        ):
            raise PlanningError(
                f"max_node_deviation = {self.max_node_deviation!r} must be a finite number > 0"
            )
        if not (math.isfinite(self.verify_step_m) and self.verify_step_m > 0):
            raise PlanningError(f"verify_step_m = {self.verify_step_m!r} m must be a finite number > 0")

    @classmethod
    def from_flat(cls, values: Mapping[str, Any]) -> PlannerSettings:
        """Settings from the scene file's flat ``planner:`` block (firefly keys included)."""
        return cls().updated(**values)

    def updated(self, **changes: Any) -> PlannerSettings:
        """A copy with ``changes``; the firefly's keys (``fireflies``, ``alpha``, ...) go to :attr:`firefly`.

        Raises:
            PlanningError: an unknown key, or a value the settings refuse.
        """
        own = {f.name for f in dataclasses.fields(self)} - {"firefly"}
        unknown = sorted(set(changes) - own - _FIREFLY_FIELDS)
        if unknown:
            raise PlanningError(
                f"unknown planner setting(s) {unknown}; allowed: {sorted(own | _FIREFLY_FIELDS)}"
            )
        firefly = {k: v for k, v in changes.items() if k in _FIREFLY_FIELDS}
        rest = {k: v for k, v in changes.items() if k in own}
        if firefly:
            rest["firefly"] = dataclasses.replace(self.firefly, **firefly)
        return dataclasses.replace(self, **rest)

    def flat(self) -> dict[str, Any]:
        """The scene file's flat ``planner:`` block: firefly keys first, then the planner's."""
        values = dataclasses.asdict(self.firefly)
        values.update(
            {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "firefly"}
        )
        return values


@dataclass(frozen=True)
class Scene:
    """A planning problem.

    Attributes:
        start: where the robot stands.
        goal: where it must go.
        obstacles: static obstacles, unique names.
        safety_margin: required clearance between every robot geometry and every obstacle [m].
        duration: trajectory duration [s]; ``None``: the fastest timing within the joints'
            velocity, acceleration and jerk limits.
        robot: URDF of the robot; ``None``: the bundled CPR.
        planner: planner settings.
        spline: spline settings (default :data:`DEFAULT_SPLINE`).
        name: a name for reports.
    """

    start: Target
    goal: Target
    obstacles: tuple[ck.Obstacle, ...] = ()
    safety_margin: float = DEFAULT_SAFETY_MARGIN_M
    duration: float | None = None
    robot: Path | None = None
    planner: PlannerSettings = field(default_factory=PlannerSettings)
    spline: SplineSettings = DEFAULT_SPLINE
    name: str = "scene"

    def __post_init__(self) -> None:
        if not (
            isinstance(self.safety_margin, int | float)
            and math.isfinite(self.safety_margin)
            and self.safety_margin >= 0
        ):
            raise PlanningError(f"safety_margin = {self.safety_margin!r} m must be a finite number >= 0")
        if self.duration is not None and not (math.isfinite(self.duration) and self.duration > 0):
            raise PlanningError(f"duration = {self.duration!r} s must be a finite number > 0 (or omitted)")
        object.__setattr__(self, "obstacles", tuple(self.obstacles))
