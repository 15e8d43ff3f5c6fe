"""How a candidate's terms become its fitness: the ``clearance`` and ``paper`` rules.

The scene's ``planner.fitness`` names one of :data:`FITNESS_RULES`; the objective
(:mod:`planning.pipeline.objective`) asks it two things:

- which distances to compute where a sample violates the required clearance
  (:meth:`FitnessRule.shortfall_distances`);
- the fitness of each candidate from its terms (:meth:`FitnessRule.fitness`).

Both rules rank a feasible candidate by ``F = time + (w_sol / w_max) IPO`` (paper eq. 4),
every feasible value at or below ``t_max``, and every infeasible one above it.

- ``paper``: effector only violates: ``2 t_max - F`` (eq. 5); links violate ("shoulder",
  with or without the effector), or another limit is broken: ``2 t_max + F`` (our reading of
  eq. 6). Distances per collision group.
- ``clearance`` (default): ``2 t_max + t_max (depth / required + excess)``, with ``depth``
  the mean violation of the required clearance over the samples [m] and ``excess`` the sum
  of the other violations, each relative to its bound: the search is led towards
  feasibility. One distance query per sample, the violation going to the closest pair's
  group. With the duration free, ``time`` is how fast the path itself can be run
  (:attr:`FitnessRule.ranks_by_duration`), not the paper's point-to-point proxy.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Terms:
    """The terms a fitness rule combines, for ``S`` candidates (each ``(S,)``).

    Attributes:
        base: ``time + (w_sol / w_max) IPO`` [s].
        feasible: no violation at all.
        links_violate: base, column, carriage or arm comes closer than the required clearance.
        depth_m: mean violation of the required clearance over the samples checked [m].
        excess: the other violations (joint range, limits, node deviation), relative, summed.
        t_max: the objective's bound of feasible values [s].
        required_m: the clearance the fitness requires [m].
    """

    base: FloatArray
    feasible: BoolArray
    links_violate: BoolArray
    depth_m: FloatArray
    excess: FloatArray
    t_max: float
    required_m: float


class FitnessRule(Protocol):
    """A fitness rule (module docstring)."""

    @property
    def ranks_by_duration(self) -> bool:
        """With the duration free, rank feasible candidates by how fast their path can be run."""
        ...

    def shortfall_distances(
        self,
        world: ck.CollisionWorld,
        configurations: FloatArray,
        required_m: float,
        pair_group: NDArray[np.intp],
    ) -> FloatArray:
        """``(n, 2)`` per-group clearance of flagged configurations [m] (``inf``: not the closest)."""
        ...

    def fitness(self, terms: Terms) -> FloatArray:
        """``(S,)`` fitness of the candidates, lower is better."""
        ...


@dataclass(frozen=True)
class PaperFitness:
    """The paper's eq. 4-6 (module docstring)."""

    ranks_by_duration: bool = False

    def shortfall_distances(  # noqa: D102 - the protocol's
        self,
        world: ck.CollisionWorld,
        configurations: FloatArray,
        required_m: float,
        pair_group: NDArray[np.intp],
    ) -> FloatArray:
        return np.asarray(world.clearance_batch(configurations).clearance_m)

    def fitness(self, terms: Terms) -> FloatArray:  # noqa: D102
        t_max, base = terms.t_max, terms.base
        shoulder = terms.links_violate | (terms.excess > 0)
        return np.where(terms.feasible, base, np.where(shoulder, 2 * t_max + base, 2 * t_max - base))


@dataclass(frozen=True)
class ClearanceFitness:
    """Feasible first, infeasible ranked by how deep it violates (module docstring)."""

    ranks_by_duration: bool = True

    def shortfall_distances(  # noqa: D102 - the protocol's
        self,
        world: ck.CollisionWorld,
        configurations: FloatArray,
        required_m: float,
        pair_group: NDArray[np.intp],
    ) -> FloatArray:
        values = np.full((len(configurations), 2), np.inf)
        distance, pair = world.min_clearance_batch(configurations, below_m=required_m)
        values[np.arange(len(configurations)), pair_group[pair]] = distance
        return values

    def fitness(self, terms: Terms) -> FloatArray:  # noqa: D102
        penalty = terms.t_max * (terms.depth_m / max(terms.required_m, 1e-3) + terms.excess)
        return np.where(terms.feasible, terms.base, 2 * terms.t_max + penalty)


FITNESS_RULES: dict[str, FitnessRule] = {"clearance": ClearanceFitness(), "paper": PaperFitness()}
"""The rules by the scene file's name (``planner.fitness``)."""
