"""The planner's settings: what a scene's ``planner:`` block may set, validated on construction.

Every default lives here once (the fields of :class:`PlannerSettings`, with its nested
:class:`~planning.search.firefly_settings.FireflySettings` and
:class:`~planning.pipeline.tuning.SearchTuning`); the scene file's schema
(:mod:`planning.io.scene_schema`) reads its defaults from them. Why the defaults are what
they are: ``docs/tuning.md``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from cpr_kin.common.names import shown
from planning.errors import PlanningError
from planning.pipeline.tuning import SearchTuning
from planning.search.firefly_settings import MAX_ITERATIONS, FireflySettings
from planning.search.refinement_settings import STALL_GENERATIONS
from planning.validation import integer_in, number_in

Fitness = Literal["clearance", "paper"]
PathKind = Literal["spline", "ptp"]
Seeding = Literal["paths", "none"]
Refine = Literal["cma", "none"]

DEFAULT_FIREFLY = FireflySettings(fireflies=30, iterations=50, alpha=0.5, stall_iterations=4)
"""The planner's firefly: the paper's parameters (:class:`FireflySettings`'s defaults) with
fewer fireflies, smaller random steps and an early stop once its best stalls for 4
iterations, after which the CMA-ES refinement (``refine: cma``) takes over."""

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
MAX_SEED = 2**63 - 1
"""Largest seed (it is stored in the trajectory file as a JSON integer)."""
MAX_TIME_LIMIT_S = 86_400.0
"""Longest ``time_limit_s`` [s] (a day)."""

_FIREFLY_FIELDS = frozenset(f.name for f in dataclasses.fields(FireflySettings))


def recorded_step_m(value: Any, where: str) -> float | None:
    """A file's recorded certified step [m] (``certified_step``), checked; ``None`` where absent.

    Raises:
        PlanningError: not a number within :data:`VERIFY_STEP_RANGE_M` (a step ``cpr-plan
            check`` may take: a smaller one would make it run on for hours); ``where`` names the key.
    """
    if value is None:
        return None
    try:  # the settings' rule for a number in a range; the message says what a file should hold
        return number_in(where, value, *VERIFY_STEP_RANGE_M, unit="m")
    except PlanningError:
        low, high = VERIFY_STEP_RANGE_M
        raise PlanningError(
            f"{where} = {value!r} is not a step in [{low:g}, {high:g}] m; "
            "give the step the trajectory was certified at, or leave the key out"
        ) from None


@dataclass(frozen=True)
class PlannerSettings:
    """Settings of the waypoint planner; validated on construction.

    Attributes:
        firefly: the firefly algorithm's parameters (default :data:`DEFAULT_FIREFLY`).
        waypoints: number of intermediate waypoints p, at most :data:`MAX_WAYPOINTS` (the
            paper: 3); a sampled path's seed takes one per corner of the path up to
            :attr:`~planning.pipeline.tuning.SeedingTuning.corner_waypoints`, never fewer.
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
        self_verify_step_m: the same for the robot's own link pairs [m], in
            :data:`VERIFY_STEP_RANGE_M`: motion of one link of a pair against the other
            between two checks; the fitness requires this much beyond the self margin. Never
            coarser than ``verify_step_m`` (:attr:`self_step_m`). Finer by default: a pair
            moves against itself a tenth as fast as the hand in the world, so its checks
            cost little, and a grasp often holds the wrist within millimetres of the forearm
            all the way out (``docs/tuning.md``).
        max_node_deviation: largest spline node deviation a candidate may have [rad or m];
            ``None`` (default): no bound. The paper case requires 20e-6.
        moving_joints: joints the waypoints move; default: every joint but the robot's wrist
            joints (:attr:`cpr_kin.Robot.wrist_joints`), and a wrist joint when start and goal
            differ in it.
        seeding: ``"paths"`` (default): the search starts from the straight line and, when
            that is blocked, from a sampling planner's path, with more waypoints if the
            path needs them (:mod:`planning.pipeline.seeding`); ``"none"`` (the paper): from a
            random population only.
        refine: ``"cma"`` (default): once the firefly stops, a CMA-ES started at its best
            (feasible or not) refines it within the rest of the evaluation budget
            (:mod:`planning.search.refinement`); ``"none"`` (the paper): the firefly's best.
        refine_stall: generations in a row without a relative improvement of
            :data:`~planning.search.optimizer.STALL_TOLERANCE` that end the refinement,
            counted once its best is within ``tuning.refinement.near_bound`` times the
            objective's lower bound, in [0, ``MAX_ITERATIONS``]; 0: run it to the evaluation
            budget (better fitness for more planning time); default
            :data:`~planning.search.refinement_settings.STALL_GENERATIONS`.
        time_limit_s: the search's time limit [s], from its start (the problem built: the
            robot loaded, start and goal solved), in (0, :data:`MAX_TIME_LIMIT_S`];
            ``None`` (default): none. When it passes the plan stops searching, times and
            verifies what it has found and returns it, or says "no solution" naming the
            limit (:mod:`planning.pipeline.deadline`; MoveIt's ``allowed_planning_time``).
        tuning: the search's internal knobs (:class:`~planning.pipeline.tuning.SearchTuning`),
            set from Python only: a scene file does not hold them.
    """

    firefly: FireflySettings = DEFAULT_FIREFLY
    waypoints: int = 2
    fitness: Fitness = "clearance"
    seed: int = 0
    path: PathKind = "spline"
    ipo: float = 0.012
    fitness_samples: int = 64
    verify_step_m: float = 0.005
    self_verify_step_m: float = 0.001
    max_node_deviation: float | None = None
    moving_joints: tuple[str, ...] | None = None
    seeding: Seeding = "paths"
    refine: Refine = "cma"
    refine_stall: int = STALL_GENERATIONS
    time_limit_s: float | None = None
    tuning: SearchTuning = field(default_factory=SearchTuning)

    def __post_init__(self) -> None:
        if not isinstance(self.firefly, FireflySettings):
            raise PlanningError(f"firefly = {shown(self.firefly)} must be a FireflySettings")
        if not isinstance(self.tuning, SearchTuning):
            raise PlanningError(f"tuning = {shown(self.tuning)} must be a SearchTuning")
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
        number_in("self_verify_step_m", self.self_verify_step_m, *VERIFY_STEP_RANGE_M, unit="m")
        if self.time_limit_s is not None:
            number_in("time_limit_s", self.time_limit_s, 0.0, MAX_TIME_LIMIT_S, low_open=True, unit="s")
        if self.moving_joints is not None:
            names = list(self.moving_joints)
            if len(set(names)) != len(names):
                raise PlanningError(f"moving_joints = {shown(names)} names a joint twice")

    @classmethod
    def from_flat(cls, values: Mapping[str, Any]) -> PlannerSettings:
        """Settings from the scene file's flat ``planner:`` block (firefly keys included)."""
        return cls().updated(**values)

    @property
    def self_step_m(self) -> float:
        """The certified self check's step [m]: ``self_verify_step_m``, at most ``verify_step_m``."""
        return min(self.self_verify_step_m, self.verify_step_m)

    @property
    def finer_verify_step_m(self) -> float:
        """The check step [m] tried where margin plus step leaves no way: ``finer_step`` of it, floored."""
        return max(self.verify_step_m * self.tuning.seeding.finer_step, VERIFY_STEP_RANGE_M[0])

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
        """The scene file's flat ``planner:`` block: firefly keys first, then the planner's.

        ``tuning`` is not part of it (a scene file does not hold it).
        """
        values = dataclasses.asdict(self.firefly)
        own = (f.name for f in dataclasses.fields(self) if f.name not in ("firefly", "tuning"))
        values.update({name: getattr(self, name) for name in own})
        return values
