"""The search's tuning knobs, in one frozen dataclass: :class:`SearchTuning`.

The planner settings (:class:`~planning.pipeline.settings.PlannerSettings`) hold what a
scene file may set; the knobs below are the planner's internals, set from Python
(``PlannerSettings(tuning=SearchTuning(...))``), as ``scripts/study_parameters.py`` does to
measure them. Why each default is what it is: ``docs/tuning.md``.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

from planning.errors import PlanningError
from planning.search.refinement_settings import RefinementSettings
from planning.search.rrt_settings import JOINT_SHORTCUTS, LOCAL_SHARE, LOCAL_SPREAD
from planning.validation import boolean, integer_in, number_in


@dataclass(frozen=True)
class SeedingTuning:
    """Where the search starts (:mod:`planning.pipeline.seeding`).

    Attributes:
        share: share of the population that starts at or around the seeds, in (0, 1].
        spread: standard deviation of the moves around a seed [share of each variable's
            range], in [0, 1].
        max_resolution_m: spacing of the sampling planner's edge checks while its trees
            grow [m], in (0, 1]; its path's edges are then checked as far apart as the
            clearance the fitness requires (at least 1 cm), when that is less.
        path_attempts: most RRT-Connect paths drawn while the spline through a path's
            waypoints violates the clearance, in [1, 20].
        redraw_samples: another path is drawn only while the paths drawn so far took fewer
            random samples than this in all, and it may take only what remains of them, in
            [0, 100000]: a path found quickly is worth another try, one that took thousands
            of samples costs as much again (the search's retries with more waypoints repair
            its spline instead).
        max_samples: random samples after which RRT-Connect gives up on a path, in
            [1, 100000] (a narrow passage may need tens of thousands; a failed draw costs
            about 0.1 ms a sample on the CPR, so the default gives up after about the 5 s
            OMPL's peer is given). A plan with a time limit draws until the limit instead
            (:func:`~planning.pipeline.path_seeds.draw_samples`).
        finer_after: random samples RRT-Connect draws keeping the margin plus the whole
            verification step before its trees go on keeping only the finer step's
            clearance (where ``finer_step`` makes one), in [1, 100000]: a passage narrower
            than margin plus step would take all ``max_samples`` in vain.
        more_waypoints: how many waypoints beyond the path's corners the seeding may add,
            two at a time, in [0, 20].
        corner_waypoints: the most waypoints a sampled path's seed takes, one per interior
            corner of the path (never fewer than the planner's ``waypoints``), in [1, 20]:
            a path of one or two corners is followed by two waypoints, whose search converges
            further in the refinement's generations than three's (``docs/tuning.md``).
        finer_step: when RRT-Connect finds no path keeping the margin plus the verification
            step clear, the share of the step tried once more, in (0, 1): a finer certified
            check lets a path pass closer to the margin (a passage narrower than the margin
            plus the step). The verification step never goes below the smallest allowed.
        local_share: share of RRT-Connect's samples drawn near a node of the tree they
            extend, in [0, 1] (:mod:`planning.search.rrt_connect`): a tree trapped in a
            pocket about a goal in a shelf grows out of it; 0: uniform samples only.
        local_spread: standard deviation of those samples about their node [share of each
            joint's range], in (0, 1].
        joint_shortcuts: attempts to straighten one joint of RRT-Connect's path where that
            makes it faster at the joints' velocity limits, in [0, 10000]
            (:func:`planning.search.edges.straighten_joints`); 0: none.
        placements: the waypoint placements along a path offered as its seed, each a share
            of the way from the corners' placement (0) to the evenly spaced one (1), in
            [0, 1] (:func:`~planning.search.waypoints.placements_along`); the best of them
            seeds the search.
    """

    share: float = 0.6
    spread: float = 0.01
    max_resolution_m: float = 0.04
    path_attempts: int = 3
    redraw_samples: int = 300
    max_samples: int = 50_000
    finer_after: int = 3_000
    more_waypoints: int = 6
    corner_waypoints: int = 3
    finer_step: float = 0.2
    local_share: float = LOCAL_SHARE
    local_spread: float = LOCAL_SPREAD
    joint_shortcuts: int = JOINT_SHORTCUTS
    placements: tuple[float, ...] = (0.0, 0.5, 1.0)

    def __post_init__(self) -> None:
        number_in("share", self.share, 0.0, 1.0, low_open=True)
        number_in("spread", self.spread, 0.0, 1.0)
        number_in("max_resolution_m", self.max_resolution_m, 0.0, 1.0, unit="m", low_open=True)
        integer_in("path_attempts", self.path_attempts, 1, 20)
        integer_in("redraw_samples", self.redraw_samples, 0, 100_000)
        integer_in("max_samples", self.max_samples, 1, 100_000)
        integer_in("finer_after", self.finer_after, 1, 100_000)
        integer_in("more_waypoints", self.more_waypoints, 0, 20)
        integer_in("corner_waypoints", self.corner_waypoints, 1, 20)
        number_in("finer_step", self.finer_step, 0.0, 1.0, low_open=True)
        number_in("local_share", self.local_share, 0.0, 1.0)
        number_in("local_spread", self.local_spread, 0.0, 1.0, low_open=True)
        integer_in("joint_shortcuts", self.joint_shortcuts, 0, 10_000)
        shares = tuple(self.placements)
        if not shares:
            raise PlanningError("placements = [] must hold at least one share in [0, 1]")
        for k, share in enumerate(shares):
            number_in(f"placements[{k}]", share, 0.0, 1.0)
        object.__setattr__(self, "placements", shares)


@dataclass(frozen=True)
class SearchTuning:
    """The planner's internal knobs, each with its measured default.

    Attributes:
        seeding: where the search starts.
        refinement: the CMA-ES refinement's step and stopping rules (its run length is the
            planner setting ``refine_stall``).
        retries: with ``seeding: paths``, how many times a failed search is tried again
            (with more waypoints, or twice the fitness samples), in [0, 10].
        preferred_first: how many candidates have their preferred timing verified before
            any falls back to a slower one, in [1, 100].
        narrowed_acceleration: shares of the acceleration limits of the narrowed timings,
            tried in turn once a fastest timing fails the certified check; each in (0, 1),
            decreasing.
        foresight_step_share: how much of the verification step beyond the margin (and of
            the self step beyond the self margin) the samples of a candidate's path, moved
            where the fastest timing's averages take them, must keep for its fastest timing
            to be tried among the first (:func:`~planning.pipeline.choose.foreseen_clear`),
            in [0, 1].
        explore_feasible_seed: the firefly explores before the refinement even when a seed
            (the straight line's or the sampling planner's) is feasible; by default the
            refinement then starts from it at once.
        explore_path_seed: the firefly explores before the refinement when no seed is
            feasible but one follows the sampling planner's path; by default the
            refinement starts from the best seed at once (the spline through the path's
            waypoints misses its corners by millimetres, which the refinement's small steps
            repair and the firefly's random population does not). The firefly runs
            whenever the seeds hold no such path (:func:`~planning.pipeline.search.explores`).
    """

    seeding: SeedingTuning = field(default_factory=SeedingTuning)
    refinement: RefinementSettings = field(default_factory=RefinementSettings)
    retries: int = 2
    preferred_first: int = 3
    narrowed_acceleration: tuple[float, ...] = (0.7, 0.5, 0.35)
    foresight_step_share: float = 0.6
    explore_feasible_seed: bool = False
    explore_path_seed: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.seeding, SeedingTuning) or not isinstance(self.refinement, RefinementSettings):
            raise PlanningError("seeding and refinement must be a SeedingTuning and a RefinementSettings")
        integer_in("retries", self.retries, 0, 10)
        boolean("explore_feasible_seed", self.explore_feasible_seed)
        boolean("explore_path_seed", self.explore_path_seed)
        integer_in("preferred_first", self.preferred_first, 1, 100)
        number_in("foresight_step_share", self.foresight_step_share, 0.0, 1.0)
        shares = tuple(self.narrowed_acceleration)
        for k, share in enumerate(shares):
            number_in(f"narrowed_acceleration[{k}]", share, 0.0, 1.0, low_open=True)
        if any(later >= earlier for earlier, later in itertools.pairwise(shares)) or 1.0 in shares:
            raise PlanningError(f"narrowed_acceleration = {list(shares)} must decrease, each share below 1")
        object.__setattr__(self, "narrowed_acceleration", shares)
