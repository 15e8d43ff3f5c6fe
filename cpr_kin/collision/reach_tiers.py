"""A group's least pair bound at many configurations, a far pair bounded only where it may be the least.

Each of a world's pairs has a reach distance: a lower bound of its distance in any
configuration (:func:`~cpr_kin.collision.robot_reach.sphere_reach_distances`). A pair's capsule
bound at a configuration (:mod:`cpr_kin.bounds.pair_bounds`) is another, so the larger of the
two is one too, and that is each pair's bound here. A certified check asks for each group's
least bound at every sample of a curve (thousands); an obstacle out of the robot's reach (a
room's clutter, a point cloud's far blocks) cannot hold it at a configuration where another
pair's bound is below its reach distance. So the pairs of a group are split into tiers by reach
distance (edges :data:`TIER_EDGES_M`, at least :data:`MIN_TIER_PAIRS` pairs a tier), the nearest
first; for the least, a tier is bounded only at the configurations whose least so far is above
the tier's least reach distance. The least is the same as with every pair bounded. The closest
pair's search (a few configurations) gets every pair's bound.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.pair_bounds import PairBounds

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

TIER_EDGES_M = (0.0, 0.05, 0.1, 0.2, 0.4, 0.8, 1.6)
"""Upper edges of the tiers' reach distances [m] (the last tier holds the pairs beyond the last
edge). The bounds are the same whatever the edges; they decide how few pairs are bounded where
the robot comes near something and how many calls a batch takes."""
MIN_TIER_PAIRS = 64
"""A tier of fewer pairs takes in the next (farther) ones until it holds this many: a call's
cost, not its pairs', is most of a small tier's (a robot among a few obstacles has one tier)."""

BoundsOf = Callable[[tuple[bool, ...]], PairBounds]
"""The pair bounds of the world's pairs flagged true (one flag per pair, in the world's order)."""


@dataclass(frozen=True)
class _Tier:
    """Pairs of one group and one tier: their positions among the group's pairs, reach, bounds."""

    columns: IntArray
    reach_m: FloatArray
    bounds: PairBounds

    @property
    def least_reach_m(self) -> float:
        """The least reach distance of the tier's pairs [m]."""
        return float(self.reach_m.min())


class ReachTiers:
    """The pairs of each group in tiers of reach distance; their bounds at a batch (module docstring).

    Args:
        reach_m: ``(P,)`` each pair's reach distance [m] (a lower bound in any configuration).
        pair_group: ``(P,)`` each pair's group index.
        bounds_of: the pair bounds of a subset of the pairs (a world's, kept per subset).
    """

    def __init__(self, reach_m: FloatArray, pair_group: IntArray, bounds_of: BoundsOf) -> None:
        self._reach = np.asarray(reach_m, dtype=float)
        self._pair_group = np.asarray(pair_group, dtype=np.int64)
        self._bounds_of = bounds_of
        self._tiers: dict[int, tuple[_Tier, ...]] = {}

    def columns(self, group: int) -> IntArray:
        """The indices of group ``group``'s pairs among the world's, ascending."""
        return np.flatnonzero(self._pair_group == group)

    def group_least(self, batch: FloatArray, group: int) -> FloatArray:
        """``(N,)`` group ``group``'s least pair bound [m] at ``batch`` ``(N, nq)`` (``inf``: no pair).

        The least of :meth:`group_bounds`' row, each tier bounded only where it may hold it.
        """
        least = np.full(len(batch), np.inf)
        for tier in self._group_tiers(group):
            rows = np.flatnonzero(least > tier.least_reach_m)
            if not rows.size:
                break  # the tiers' reach ascends and the least only falls: none further
            whole = rows.size == len(batch)
            values = np.maximum(tier.bounds(batch if whole else batch[rows]), tier.reach_m)
            least[rows] = np.minimum(least[rows], values.min(axis=1))
        return least

    def least(self, batch: FloatArray, groups: int, per_pair_m: FloatArray | None = None) -> FloatArray:
        """``(N, groups)`` each group's :meth:`group_least` at ``batch``, ``inf`` for a group with no pair.

        Of ``per_pair_m`` ``(N, P)`` where given (every pair's bounds, already computed).
        """
        least = np.full((len(batch), groups), np.inf)
        for group in range(groups):
            columns = self.columns(group)
            if columns.size and per_pair_m is not None:
                least[:, group] = per_pair_m[:, columns].min(axis=1)
            elif columns.size:
                least[:, group] = self.group_least(batch, group)
        return least

    def group_bounds(self, batch: FloatArray, group: int) -> FloatArray:
        """``(N, n)`` lower bounds [m] of group ``group``'s ``n`` pairs (:meth:`columns`) at ``batch``.

        Each the larger of the pair's capsule bound and its reach distance, every tier bounded:
        a search for the closest pair (:func:`~cpr_kin.collision.closest_pairs.closest_pairs`)
        visits the pairs in the order of these and stops at the first no nearer than what it found.
        """
        out = np.empty((len(batch), len(self.columns(group))))
        for tier in self._group_tiers(group):
            out[:, tier.columns] = np.maximum(tier.bounds(batch), tier.reach_m)
        return out

    def _group_tiers(self, group: int) -> tuple[_Tier, ...]:
        """Group ``group``'s tiers, nearest first, built once."""
        if group not in self._tiers:
            columns = self.columns(group)
            reach = self._reach[columns]
            tier_of = np.searchsorted(np.asarray(TIER_EDGES_M), reach, side="left")
            groups: list[list[int]] = []
            for tier in sorted(set(tier_of.tolist())):  # np.unique imports numpy.ma into a new process
                if groups and len(groups[-1]) < MIN_TIER_PAIRS:
                    groups[-1] += np.flatnonzero(tier_of == tier).tolist()
                else:
                    groups.append(np.flatnonzero(tier_of == tier).tolist())
            tiers = []
            for members in groups:
                local = np.sort(np.array(members, dtype=np.int64))  # the bounds' columns: the world's order
                active = np.zeros(len(self._reach), dtype=bool)
                active[columns[local]] = True
                tiers.append(_Tier(local, reach[local], self._bounds_of(tuple(active.tolist()))))
            self._tiers[group] = tuple(tiers)
        return self._tiers[group]
