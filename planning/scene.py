"""What to plan: the robot, the obstacles, the start and goal, the margin and the settings."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SplineSettings
from planning.errors import PlanningError
from planning.search.firefly import FireflySettings, Mode

FloatArray = NDArray[np.float64]
Fitness = Literal["clearance", "paper"]
PathKind = Literal["spline", "ptp"]


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
    """Settings of the firefly waypoint planner; validated on construction.

    Attributes:
        fireflies: population size. The paper: 50.
        iterations: firefly iterations. The paper: 50.
        alpha: initial randomisation (normalised units). The paper: 1.
        beta0: attractiveness at distance 0. The paper: 0.5.
        gamma: light absorption (normalised units).
        theta: per-iteration decay of alpha.
        waypoints: number of intermediate waypoints p. The paper: 3.
        mode: ``"sweep"`` (vectorised) or ``"sequential"`` (NiaPy's semantics).
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

    # the firefly's parameters and their defaults are FireflySettings'
    fireflies: int = FireflySettings.fireflies
    iterations: int = FireflySettings.iterations
    alpha: float = FireflySettings.alpha
    beta0: float = FireflySettings.beta0
    gamma: float = FireflySettings.gamma
    theta: float = FireflySettings.theta
    waypoints: int = 3
    mode: Mode = FireflySettings.mode
    fitness: Fitness = "clearance"
    seed: int = 0
    path: PathKind = "spline"
    ipo: float = 0.012
    fitness_samples: int = 64
    verify_step_m: float = 0.005
    max_node_deviation: float | None = None
    moving_joints: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        self.firefly()  # validates the firefly parameters
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

    def firefly(self) -> FireflySettings:
        """The firefly algorithm's part of these settings."""
        return FireflySettings(
            fireflies=self.fireflies,
            iterations=self.iterations,
            alpha=self.alpha,
            beta0=self.beta0,
            gamma=self.gamma,
            theta=self.theta,
            mode=self.mode,
        )


@dataclass(frozen=True)
class Scene:
    """A planning problem.

    Attributes:
        start: where the robot stands.
        goal: where it must go.
        obstacles: static obstacles, unique names.
        safety_margin: required clearance between every robot geometry and every obstacle [m].
        duration: trajectory duration [s]; ``None``: the fastest uniform timing within the
            joints' velocity, acceleration and jerk limits.
        robot: URDF of the robot; ``None``: the bundled CPR.
        planner: planner settings.
        spline: spline settings (default: p = 1e6, jerk only, rest-to-rest ends).
        name: a name for reports.
    """

    start: Target
    goal: Target
    obstacles: tuple[ck.Obstacle, ...] = ()
    safety_margin: float = 0.1
    duration: float | None = None
    robot: Path | None = None
    planner: PlannerSettings = field(default_factory=PlannerSettings)
    spline: SplineSettings = field(
        default_factory=lambda: SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
    )
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


PAPER_START_TCP = (0.5, 0.45, 0.25)
PAPER_GOAL_TCP = (-0.5, 0.45, 0.25)


def paper_scene(seed: int = 0, **planner_overrides: object) -> Scene:
    """The paper case (DESIGN.md section 4) with the paper's parameters.

    Start TCP (0.5, 0.45, 0.25), goal (-0.5, 0.45, 0.25), a 0.3 m cube centred at
    (0, 0.6, 0.15), margin 0.1 m; n = 50, alpha = 1, beta0 = 0.5, 50 iterations, 3
    waypoints, node deviation at most 20 um; spline N = 4, h = 1 s (4 s), p = 1e6, jerk
    only, natural ends.
    """
    parameters: dict[str, object] = {
        "fireflies": 50,
        "iterations": 50,
        "alpha": 1.0,
        "beta0": 0.5,
        "waypoints": 3,
        "max_node_deviation": 20e-6,
    }
    parameters.update(planner_overrides, seed=seed)
    planner = PlannerSettings(**parameters)  # type: ignore[arg-type]
    return Scene(
        name="paper",
        start=Target(tcp=PAPER_START_TCP),
        goal=Target(tcp=PAPER_GOAL_TCP),
        obstacles=(ck.Obstacle.box((0.3, 0.3, 0.3), (0.0, 0.6, 0.15), name="crate"),),
        safety_margin=0.1,
        duration=4.0,
        planner=planner,
        spline=SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="natural"),
    )
