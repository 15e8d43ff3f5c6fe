"""Settings of the CMA-ES refinement (:mod:`planning.search.refinement`), validated on construction.

Why each default is what it is, with the measurements behind it: ``docs/tuning.md``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from planning.errors import PlanningError
from planning.validation import boolean, number_in

STALL_GENERATIONS = 4
"""Generations in a row without a relative improvement of ``stall_tolerance`` that end the
refinement (the planner setting ``refine_stall``; 0: run to the budget)."""


@dataclass(frozen=True)
class RefinementSettings:
    """How the CMA-ES refinement steps and when it stops; validated on construction.

    Attributes:
        sigma: initial step from a feasible start [share of each variable's range], in
            (0, 1]: the search's best lies in the right basin, and a feasible one on the
            clearance, so the refinement starts local.
        active: the active covariance update of Hansen's tutorial: the worse half of each
            generation shrinks the covariance along its steps (a constraint's normal, where
            the refinement's best presses against the clearance).
        near_bound: how close to the objective's lower bound (a ratio >= 1) the best must be
            before stalled generations count towards the early stop; farther, the
            refinement runs on until its step collapses or the budget ends. ``inf``: every
            stall counts.
        min_sigma: step below which the refinement ends [share of the range], in
            (0, ``min(sigma, infeasible_sigma)``]: below what the timing or the clearance can
            tell apart.
        fallback_spacing: least fitness between two of the refinement's points kept as
            fallbacks, as a share of its whole improvement, in [0, 1].
        infeasible_sigma: initial step from an infeasible start (the spline through a
            sampled path's waypoints that cuts a corner) [share of each variable's range],
            in (0, 1]: the way to feasibility is farther than a polish.

    A generation stalls when it improves the best value by less than a relative
    :data:`~planning.search.optimizer.STALL_TOLERANCE` (the firefly's definition too).
    """

    sigma: float = 0.015
    active: bool = True
    near_bound: float = 1.3
    min_sigma: float = 1e-4
    fallback_spacing: float = 1 / 8
    infeasible_sigma: float = 0.03

    def __post_init__(self) -> None:
        number_in("sigma", self.sigma, 0.0, 1.0, low_open=True)
        number_in("infeasible_sigma", self.infeasible_sigma, 0.0, 1.0, low_open=True)
        boolean("active", self.active)
        if not (isinstance(self.near_bound, int | float) and self.near_bound >= 1.0):
            raise PlanningError(f"near_bound = {self.near_bound!r} must be a number >= 1 (or inf)")
        number_in("min_sigma", self.min_sigma, 0.0, min(self.sigma, self.infeasible_sigma), low_open=True)
        number_in("fallback_spacing", self.fallback_spacing, 0.0, 1.0)
        if math.isnan(self.near_bound):
            raise PlanningError("near_bound = nan must be a number >= 1 (or inf)")
