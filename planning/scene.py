"""What to plan: the robot, the obstacles, the start and goal, the margin and the settings.

Every default lives here once: :data:`DEFAULT_SAFETY_MARGIN_M`, :data:`DEFAULT_SPLINE` and
the fields of :class:`PlannerSettings` (with its nested
:class:`~planning.search.firefly.FireflySettings`). The scene file's schema
(:mod:`planning.io.scene_schema`) reads its defaults from them.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.names import unprintable
from planning.curves.spline_settings import SplineSettings
from planning.errors import PlanningError
from planning.search.firefly_settings import MAX_ITERATIONS, FireflySettings
from planning.search.refinement import STALL_GENERATIONS
from planning.validation import integer_in, number_in, shown

FloatArray = NDArray[np.float64]
Fitness = Literal["clearance", "paper"]
PathKind = Literal["spline", "ptp"]
Seeding = Literal["paths", "none"]
Refine = Literal["cma", "none"]

DEFAULT_SAFETY_MARGIN_M = 0.1
"""Clearance every robot geometry keeps from every obstacle unless a scene says otherwise [m]
(the paper's value)."""

DEFAULT_SPLINE = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
"""The spline of a scene unless it says otherwise: the paper's weights, but at rest at both
ends, which a real robot needs (the paper case itself uses natural ends)."""

DEFAULT_FIREFLY = FireflySettings(fireflies=30, iterations=50, alpha=0.5, stall_iterations=4)
"""The planner's firefly: the paper's parameters (:class:`FireflySettings`'s defaults) with
fewer fireflies, smaller random steps and an early stop, backed by
``scripts/study_parameters.py`` (30 scenes, 6 of them narrow passages): seeded with paths
(:mod:`planning.seeding`), 30 fireflies plan every scene in a fraction of the paper search's
time (which misses 4 of 30). Alpha 0.5 instead of 1 shortens the trajectories by 6 %
(geometric mean); smaller alphas cost more time than they give. The firefly stops after 4
stalled iterations and hands its best to the CMA-ES refinement (``refine: cma``,
:mod:`planning.search.refinement`), which descends further per evaluation than the
firefly's late iterations: on 100 generated scenes (24 narrow) the pair gives 7-10 %
shorter trajectories (geometric mean) than 8 stalled iterations and no refinement, in the
same planning time (``scripts/bench_search.py``); in the study, the former defaults' are
10 % longer and 4 stalled iterations without the refinement 17 % longer. 2 stalled
iterations measured as well as 4 on the study's 30 scenes and worse on 100; 50 fireflies or
no early stop cost more time for less."""

PAPER_SEARCH: dict[str, Any] = {**dataclasses.asdict(FireflySettings()), "seeding": "none", "refine": "none"}
"""The paper's search as planner-setting changes (:meth:`PlannerSettings.updated`): its firefly
(:class:`FireflySettings`'s defaults: n = 50, 50 iterations, alpha 1, beta0 0.5, every
iteration) from a random population, and no refinement. ``cpr-plan plan --paper-search``
applies them."""

MAX_WAYPOINTS = 20
"""Most intermediate waypoints (the search's dimension is waypoints x moving joints)."""
MAX_FITNESS_SAMPLES = 4096
"""Most configurations checked per candidate path: with 1000 fireflies, 4096 x 5 x 8 bytes
per candidate is 160 MB of samples."""
IPO_RANGE_S = (1e-3, 1.0)
"""Allowed controller interpolation periods [s]."""
VERIFY_STEP_RANGE_M = (1e-4, 0.1)
"""Allowed robot motion between two verification checks [m]: below 0.1 mm the check of a
long trajectory takes minutes, above 0.1 m it is no check."""
MAX_SAFETY_MARGIN_M = 1.0
"""Largest safety margin [m]: the CPR reaches about 1.3 m."""
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
MAX_SEED = 2**63 - 1
"""Largest seed (it is stored in the trajectory file as a JSON integer)."""

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
        firefly: the firefly algorithm's parameters (default :data:`DEFAULT_FIREFLY`).
        waypoints: number of intermediate waypoints p, at most :data:`MAX_WAYPOINTS`. The
            paper: 3.
        fitness: ``"clearance"`` (feasible first, infeasible ranked by coal's violation
            depth) or ``"paper"`` (eq. 4-6).
        seed: seed of the random generator.
        path: what the fitness checks: the executed ``"spline"`` (default) or the
            paper's straight joint-space ``"ptp"`` moves.
        ipo: controller interpolation period [s] for w_sol, in :data:`IPO_RANGE_S`.
        fitness_samples: configurations checked per candidate path in the fitness, at most
            :data:`MAX_FITNESS_SAMPLES`.
        verify_step_m: robot motion between two checks in the final verification [m], in
            :data:`VERIFY_STEP_RANGE_M`; the fitness requires this much clearance beyond the
            margin.
        max_node_deviation: largest spline node deviation a candidate may have [rad or m];
            ``None`` (default): no bound. The paper case requires 20e-6.
        moving_joints: joints the waypoints move; default: theta1, d2, d3, and a wrist
            joint when start and goal differ in it.
        seeding: ``"paths"`` (default): the search starts from the straight line and, when
            that is blocked, from a sampling planner's path, with more waypoints if the
            path needs them (:mod:`planning.seeding`); ``"none"`` (the paper): from a
            random population only.
        refine: ``"cma"`` (default): once the firefly has a feasible best, a CMA-ES started
            at it refines it within the rest of the evaluation budget
            (:mod:`planning.search.refinement`); ``"none"`` (the paper): the firefly's best.
        refine_stall: generations in a row without a relative improvement of 0.1 % that end
            the refinement, counted once its best is within
            :data:`~planning.search.refinement.NEAR_BOUND` times the objective's lower bound,
            in [0, ``MAX_ITERATIONS``]; 0: run it to the evaluation budget (better fitness
            for more planning time, ``scripts/bench_peers.py``); default
            :data:`~planning.search.refinement.STALL_GENERATIONS`.
    """

    firefly: FireflySettings = DEFAULT_FIREFLY
    waypoints: int = 3
    fitness: Fitness = "clearance"
    seed: int = 0
    path: PathKind = "spline"
    ipo: float = 0.012
    fitness_samples: int = 64
    verify_step_m: float = 0.005
    max_node_deviation: float | None = None
    moving_joints: tuple[str, ...] | None = None
    seeding: Seeding = "paths"
    refine: Refine = "cma"
    refine_stall: int = STALL_GENERATIONS

    def __post_init__(self) -> None:
        if not isinstance(self.firefly, FireflySettings):
            raise PlanningError(f"firefly = {shown(self.firefly)} must be a FireflySettings")
        integer_in("waypoints", self.waypoints, 1, MAX_WAYPOINTS)
        if self.fitness not in ("clearance", "paper"):
            raise PlanningError(f"fitness = {shown(self.fitness)}; allowed: 'clearance', 'paper'")
        if self.seeding not in ("paths", "none"):
            raise PlanningError(f"seeding = {shown(self.seeding)}; allowed: 'paths', 'none'")
        if self.refine not in ("cma", "none"):
            raise PlanningError(f"refine = {shown(self.refine)}; allowed: 'cma', 'none'")
        integer_in("refine_stall", self.refine_stall, 0, MAX_ITERATIONS)
        if self.path not in ("spline", "ptp"):
            raise PlanningError(f"path = {shown(self.path)}; allowed: 'spline', 'ptp'")
        integer_in("seed", self.seed, 0, MAX_SEED)
        number_in("ipo", self.ipo, *IPO_RANGE_S, unit="s")
        integer_in("fitness_samples", self.fitness_samples, 2, MAX_FITNESS_SAMPLES)
        if self.max_node_deviation is not None:
            number_in("max_node_deviation", self.max_node_deviation, 0.0, 1.0, low_open=True)
        number_in("verify_step_m", self.verify_step_m, *VERIFY_STEP_RANGE_M, unit="m")
        if self.moving_joints is not None:
            names = list(self.moving_joints)
            if len(set(names)) != len(names):
                raise PlanningError(f"moving_joints = {shown(names)} names a joint twice")

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
        obstacles: static obstacles, unique names, at most :data:`MAX_OBSTACLES`.
        safety_margin: required clearance between every robot geometry and every obstacle
            [m], at most :data:`MAX_SAFETY_MARGIN_M`.
        duration: trajectory duration [s], in :data:`DURATION_RANGE_S` and at most
            :data:`MAX_IPO_SAMPLES` IPO periods; ``None``: the fastest timing within the
            joints' velocity, acceleration and jerk limits.
        robot: URDF of the robot; ``None``: the bundled CPR.
        planner: planner settings.
        spline: spline settings (default :data:`DEFAULT_SPLINE`); finite weights ``p`` in
            :data:`SPLINE_P_RANGE`, non-zero ``a_r`` in :data:`SPLINE_A_RANGE`.
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
        if not isinstance(self.name, str) or not self.name:
            raise PlanningError(f"scene name {shown(self.name)} must be a non-empty text")
        character = unprintable(self.name)
        if character is not None:
            raise PlanningError(
                f"scene name {shown(self.name)} holds {character}; names must be printable text"
            )
        number_in("safety_margin", self.safety_margin, 0.0, MAX_SAFETY_MARGIN_M, unit="m")
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
