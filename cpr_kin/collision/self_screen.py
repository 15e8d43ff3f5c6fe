"""coal's test of a robot's own pairs, screened by their bounds and the near pairs' cells.

The pairs come split into near and far (:class:`~cpr_kin.collision.self_split.SelfScreen`): the
far go to coal only where their bounds are in doubt, the near only where their cells
(:class:`~cpr_kin.collision.near_cells.NearCells`) are. The answer is coal's on every pair.
"""

from __future__ import annotations

import copy
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.collision.closest_pairs import closest_pairs
from cpr_kin.collision.coal_pools import configure_pool, pool_collisions
from cpr_kin.collision.decisive import coal_error_m
from cpr_kin.collision.self_split import TYPICAL_MARGIN_M, SelfScreen, screen_threshold
from cpr_kin.shapes.exact_pairs import ExactPairs

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


class ScreenedSelfTest:
    """coal's yes/no self-collision test, screened by the pairs' bounds.

    The pairs are split once into near and far (:class:`~cpr_kin.collision.self_split.SelfScreen`):
    the *near* go to coal at every configuration their cells do not clear
    (:class:`~cpr_kin.collision.near_cells.NearCells`; at every configuration where some near
    pair has no grid), the others (*far*) only at configurations
    where some far pair's bound is within the margin, and there only the far pairs whose
    bounds are within it in some configuration of the batch (a few of a thousand pairs on an
    arm whose hand has a dozen links). Each group has its own Pinocchio ``GeometryPool``, run
    in parallel over ``num_threads`` threads, stopping at a configuration's first hit. The
    answer is coal's on every pair.

    A pair's distance counts its allowance (:mod:`cpr_kin.bounds.close_pairs`): coal's distance plus
    ``allowance_m``, so a margin asks coal for that much less of the pair (never below contact).

    Args:
        model: the robot's Pinocchio model.
        geometry_model: its geometry model with the pairs added, in order.
        pairs: the pairs' geometry indices.
        num_threads: threads of coal's batches.
        allowance_m: ``(P,)`` each pair's allowance [m] (default: none).
        screen: the pairs' split, bounds and cells (default: built for them at
            :data:`~cpr_kin.collision.self_split.TYPICAL_MARGIN_M`; a robot's own is built once
            per margin's threshold, :func:`~cpr_kin.collision.self_split.robot_self_screen`).
        exact: the pairs on the robot's exact meshes (:mod:`cpr_kin.shapes.exact_pairs`): what the
            hulls flag, the meshes decide; default: none decides.
    """

    def __init__(
        self,
        model: Any,
        geometry_model: Any,
        pairs: Sequence[tuple[int, int]],
        num_threads: int,
        allowance_m: FloatArray | None = None,
        screen: SelfScreen | None = None,
        exact: ExactPairs | None = None,
    ) -> None:
        self.model, self.geometry_model, self.num_threads = model, geometry_model, num_threads
        self._exact = exact if exact else None
        self.allowance_m = (
            np.zeros(len(pairs)) if allowance_m is None else np.asarray(allowance_m, dtype=float)
        )
        screen = screen or SelfScreen.build(model, geometry_model, pairs, screen_threshold(TYPICAL_MARGIN_M))
        near = screen.near
        self.all_bounds, self.far_bounds = screen.all_bounds, screen.far_bounds
        self.near_pairs = tuple(p for p, is_near in zip(pairs, near, strict=True) if is_near)
        self._near = near
        self._near_cells = screen.near_cells
        self._far_index = np.flatnonzero(~near)
        self._coal_state = _CoalState(np.zeros(len(pairs), dtype=bool), np.zeros(len(pairs)))

    def on_hulls(self) -> ScreenedSelfTest:
        """The test with the hulls deciding alone, sharing its pools and data (and what they are set to)."""
        hulls = copy.copy(self)
        hulls._exact = None
        return hulls

    def violated(self, batch: FloatArray, margin_m: float, ordered: bool = False) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``batch``.

        With ``ordered``, exact up to the first violated configuration; those after it are
        reported violated, the meshes not asked about them (what an edge check needs).
        """
        self._prepare(margin_m)
        hits = np.zeros(len(batch), dtype=bool)
        if self.near_pairs and not self._near_cells:
            _settle(hits, np.arange(len(batch)), self._coal(0, batch, ordered), ordered)
        elif self.near_pairs:  # coal where their cells are in doubt
            margins = self._coal_state.near_margins
            doubtful = np.flatnonzero(self._near_cells.states(batch, margins, self._exact is not None))
            if doubtful.size:
                _settle(hits, doubtful, self._coal(0, batch[doubtful], ordered), ordered)
        if self.far_bounds.n_pairs:
            threshold = float(margin_m + coal_error_m(margin_m))
            if hits.any():
                open_rows = np.flatnonzero(~hits)
                doubtful = open_rows[self.far_bounds.any_below(batch[open_rows], threshold)]
            else:  # every row open: no copy of the batch
                doubtful = np.flatnonzero(self.far_bounds.any_below(batch, threshold))
            if doubtful.size:
                within = self.far_bounds(batch[doubtful], threshold) <= threshold
                self._switch_far(np.any(within, axis=0))
                _settle(hits, doubtful, self._coal(1, batch[doubtful], ordered), ordered)
        return hits

    def _switch_far(self, doubtful: BoolArray) -> None:
        """Make the far pool test only the far pairs ``doubtful`` ``(P_far,)``: the rest clear the margin."""
        state = self._coal_state
        wanted = np.zeros_like(state.far_on)
        wanted[self._far_index[doubtful]] = True
        changed = np.flatnonzero(wanted != state.far_on).tolist()
        for gdata in state.pools[1].getGeometryDatas():
            for p in changed:
                (gdata.activateCollisionPair if wanted[p] else gdata.deactivateCollisionPair)(p)
        state.far_on = wanted

    def distances(self, batch: FloatArray) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair (index among all pairs), ``(N,)`` each, exactly.

        coal's distance of the closest pair, the pairs visited in the order of their bounds
        until no pair left can be closer (:func:`cpr_kin.collision.closest_pairs.closest_pairs`).
        """
        bounds = self.bounds(batch)
        return self._closest(batch, bounds, np.arange(bounds.shape[1]))

    def bounds(self, batch: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of every pair's distance (its capsules') at ``batch``."""
        return self.all_bounds(batch) + self.allowance_m

    def pair_bounds(self, batch: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` lower bounds [m] of pair ``pair``'s distance (its capsules') at ``batch``."""
        return self.all_bounds.column(batch, pair) + float(self.allowance_m[pair])

    def pair_distances(self, batch: FloatArray, pair: int, exact_below_m: float = np.inf) -> FloatArray:
        """``(N,)`` coal's distance [m] of pair ``pair`` (index among all pairs) at ``batch``.

        On the exact meshes where the hulls' distance is below ``exact_below_m`` [m].
        """
        unbounded, pairs = np.full((len(batch), 1), -np.inf), np.array([pair], dtype=np.int64)
        return self._closest(batch, unbounded, pairs, exact_below_m)[0]

    def _closest(
        self, batch: FloatArray, bounds: FloatArray, pairs: IntArray, exact_below_m: float = np.inf
    ) -> tuple[FloatArray, IntArray]:
        """:func:`~cpr_kin.collision.closest_pairs.closest_pairs` of ``pairs``, bounded by ``bounds``."""
        state = self._prepare(float("nan"))
        data = (self.model, state.data, self.geometry_model, state.distance_data)
        offsets = self.allowance_m[pairs]
        return closest_pairs(
            *data, batch, bounds, pairs, offsets_m=offsets, exact=self._exact, exact_below_m=exact_below_m
        )

    def _coal(self, tier: int, batch: FloatArray, ordered: bool = False) -> NDArray[np.bool_]:
        """Coal's test of ``tier``'s pairs (0 near, 1 far) at ``batch``: the hulls flag, the meshes decide.

        ``ordered``: the meshes decide up to the first configuration they find violated.
        """
        state = self._coal_state
        flagged = pool_collisions(
            state.pools[tier], self.model, state.data, self.geometry_model, batch, self.num_threads
        )
        if self._exact is None:
            return flagged
        active = np.flatnonzero(self._near if tier == 0 else state.far_on)
        data = (self.model, state.data, self.geometry_model, state.distance_data)
        return self._exact.recheck(flagged, *data, batch, active, state.pair_margins, ordered)

    def _prepare(self, margin_m: float) -> _CoalState:
        """Build the two pools and distance data once; set their margin and pairs when the margin changes.

        A NaN ``margin_m`` leaves the margin as it is. The state is the one its copies share
        (:meth:`on_hulls`): what the pools are set to is known to every test that uses them.
        """
        state = self._coal_state
        if not state.pools:
            state.data = self.model.createData()
            state.distance_data = self.geometry_model.createData()
            pools = (pin.GeometryPool(self.model, self.geometry_model, self.num_threads) for _ in range(2))
            state.pools = list(pools)
        if margin_m != state.margin_m and not np.isnan(margin_m):
            state.pair_margins = np.maximum(margin_m - self.allowance_m, 0.0)
            state.near_margins = state.pair_margins[self._near].tolist()
            margins = state.pair_margins if self.allowance_m.any() else margin_m
            for pool, active in zip(state.pools, (self._near, state.far_on), strict=True):
                configure_pool(pool, self.geometry_model, margins, active)
                for gdata in pool.getGeometryDatas():
                    for request in gdata.collisionRequests:
                        request.enable_contact = False
            state.margin_m = margin_m
        return state


def _settle(hits: BoolArray, rows: IntArray, found: BoolArray, ordered: bool) -> None:
    """Write a test's answer ``found`` at ``rows`` of ``hits``, in place.

    ``ordered``: every configuration after the first one found is marked too (an ordered
    test's answer, which the later tiers then skip).
    """
    hits[rows] = found
    if ordered and found.any():
        hits[rows[int(np.argmax(found))] :] = True


@dataclass
class _CoalState:
    """coal's pools and data of a screened self test and what they are set to, shared by its copies.

    Attributes:
        far_on: ``(P,)`` the far pool's active pairs.
        pair_margins: ``(P,)`` each pair's coal margin [m]: the margin less its allowance.
        near_margins: the near pairs' coal margins [m], in order (what their cells must clear).
        pools: the near pairs' ``GeometryPool`` and the far pairs' (built on the first query).
        data: the model's data of single queries; distance_data: the geometry data of distances.
        margin_m: the margin [m] the pools test (NaN: none yet).
    """

    far_on: BoolArray
    pair_margins: FloatArray
    near_margins: list[float] = field(default_factory=list)
    pools: list[Any] = field(default_factory=list)
    data: Any = None
    distance_data: Any = None
    margin_m: float = float("nan")
