"""A near self pair's margin test remembered on a grid over the joints between its geometries.

A robot's *near* pairs (:class:`~cpr_kin.collision.self_split.SelfScreen`) go to coal at every
configuration: their capsules overlap, although their hulls are mostly a centimetre or more
apart. Such a pair is a link and the one two joints down the chain, and its distance depends
only on the joints between them: a grid over those (:mod:`cpr_kin.bounds.pair_cells`) holds
it, anywhere in a cell, within the pair's slack of its distance at the cell's centre.

The first configuration that falls in a cell has coal test the centre with a margin that much
larger (and :data:`TESTED_ABOVE_M` more, so that the few margins of a plan share the answer):
where the centre is clear, every configuration of the cell clears the margin, and the next
ones need no coal. A cell remembers the largest margin it cleared and the smallest it did not;
where it does not clear one, the distance measured at its centre, from which a configuration
near the centre may still clear it (:func:`~cpr_kin.bounds.pair_cells.cell_states`).
The grids are the robot's, kept across plans (:func:`~cpr_kin.collision.self_split.robot_self_screen`)
and, what they learned, across processes (:mod:`cpr_kin.collision.learned_cells`); what they
gain: ``docs/tuning.md``, Kernels.

Where a pair has an exact mesh (:mod:`cpr_kin.shapes.exact_pairs`), a test asked *on the meshes*
has the meshes decide a centre the hulls do not clear, and remembers its answers apart from the
hulls': a concave link's hull may stay within the margin over whole cells its mesh clears. The
slack holds for the meshes as for the hulls (each mesh lies within its hull, on the same link),
and a cell whose centre's meshes are apart by more than the slack cannot hold a configuration
where they touch, or where one holds the other.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import sampled_configurations
from cpr_kin.bounds.pair_cells import CLEAR, DOUBTFUL, UNKNOWN, CellGrids, cell_grids, cell_states, has_grid
from cpr_kin.bounds.reach import GeometryReach, relative_radii
from cpr_kin.collision.closest_pairs import closest_pairs
from cpr_kin.collision.coal_pools import configure_pool, pool_collisions
from cpr_kin.collision.decisive import coal_error_m
from cpr_kin.collision.learned_cells import CellMemory, LearnedCells, cells_digest
from cpr_kin.common.arrays import finite_median
from cpr_kin.shapes.exact_meshes import ExactMesh
from cpr_kin.shapes.exact_pairs import ExactPairs

FloatArray = NDArray[np.float64]
Float32Array = NDArray[np.float32]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

SLACK_SHARE = 0.5
"""A pair's slack as a share of its median distance over :data:`PROBES` random configurations."""
MIN_SLACK_M, MAX_SLACK_M = 0.002, 0.02
"""The least and the most slack of a pair [m]."""
PROBES = 256
"""Seeded random configurations on which a pair's median distance is measured."""
TESTED_ABOVE_M = 0.002
"""How much larger than asked a cell's first test is [m]: the margins of a plan differ by less."""
LEVEL_M = 0.0005
"""A margin is rounded up to a multiple of this [m] before its cells are looked up."""
MAX_POOLS = 16
"""coal's pools kept, one per pair and tested margin; more are dropped and built again."""


class NearCells:
    """The near pairs' grids (:class:`~cpr_kin.bounds.pair_cells.CellGrids`) and what their cells clear.

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: its geometry model (copied, never modified).
        pairs: the near pairs' geometry indices.
        reach: each geometry's bounds (:func:`cpr_kin.bounds.reach.geometry_reach`); default:
            within ``model``'s limits.
        exact_meshes: the robot's exact link meshes by geometry index
            (:attr:`cpr_kin.Robot.exact_meshes`), what a test on the meshes decides with
            (module docstring); default: none, the hulls decide alone.
        kept: whether what the cells learn is kept on disk for the robot's next process
            (:mod:`cpr_kin.collision.learned_cells`), and read from there now (default: not).

    A pair that cannot have a grid (:func:`~cpr_kin.bounds.pair_cells.has_grid`: more than two
    joints between its geometries) is left out: ``pairs`` holds the others, in order, and its
    pair ``k`` is collision pair ``k`` of ``geometry_model``. ``tested`` counts the cells coal has
    tested.
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        pairs: Sequence[tuple[int, int]],
        reach: Sequence[GeometryReach] | None = None,
        exact_meshes: Mapping[int, ExactMesh] | None = None,
        kept: bool = False,
    ) -> None:
        self.model = model
        self.geometry_model = _with_pairs(collision_model, pairs)
        self.grids: CellGrids | None = None
        self.pairs: tuple[tuple[int, int], ...] = ()
        if pairs:
            radii, slacks = relative_radii(model, collision_model, pairs, reach), self._slacks()
            gridded = [has_grid(model, r, s) for r, s in zip(radii, slacks.tolist(), strict=True)]
            self.pairs = tuple(p for p, g in zip(pairs, gridded, strict=True) if g)
            if not all(gridded):
                self.geometry_model = _with_pairs(collision_model, self.pairs)
                radii, slacks = radii[gridded], slacks[gridded]
            if self.pairs:
                self.grids = cell_grids(model, radii, slacks)
        size = self.grids.size if self.grids is not None else 0
        self._exact = ExactPairs(self.geometry_model, exact_meshes or {})
        digest = None
        if kept and self.grids is not None:
            digest = cells_digest(model, collision_model, self.pairs, self.grids, exact_meshes or {})
        self.memory = CellMemory(size, bool(self._exact), digest)
        self._learned = self.memory.kinds
        self._levels: dict[tuple[float, ...], Float32Array] = {}
        self._pools: dict[tuple[int, float], Any] = {}
        self._data = model.createData()
        self._geometry_data = self.geometry_model.createData()
        self.tested = 0

    def __bool__(self) -> bool:
        return self.grids is not None

    def clear(self, batch: FloatArray, margins_m: Sequence[float], on_meshes: bool = False) -> BoolArray:
        """``(N,)`` where every near pair is certainly farther than its margin ``margins_m`` [m].

        ``margins_m``: one per near pair; coal's error is added. A cell not yet tested at that
        margin (rounded up to :data:`LEVEL_M`) is tested now, at its centre. ``on_meshes``: the
        pairs' distance on their exact meshes where they have one (module docstring), else on
        the hulls.
        """
        return np.asarray(self.states(batch, margins_m, on_meshes) == CLEAR)

    def states(
        self, batch: FloatArray, margins_m: Sequence[float], on_meshes: bool = False
    ) -> NDArray[np.int8]:
        """``(N,)`` :meth:`clear` as states: ``CLEAR`` (0) where it holds, nonzero elsewhere.

        What a caller that wants the other rows takes (``np.flatnonzero``), in one step.
        """
        grids = self.grids
        if grids is None:
            return np.full(len(batch), DOUBTFUL, dtype=np.int8)
        learned = self._learned[on_meshes]
        levels = self._level(tuple(margins_m))
        cells, states = self._states(grids, batch, levels, learned)
        if states.max(initial=CLEAR) == UNKNOWN:
            unknown = np.flatnonzero(states == UNKNOWN)
            for k, level in enumerate(levels.tolist()):
                row_cells = cells[unknown, k]
                untested = (learned.cleared[row_cells] < level) & (learned.refused[row_cells] > level)
                if untested.any():
                    self._test(grids, k, level, row_cells[untested], batch[unknown[untested]], on_meshes)
            cells, states = self._states(grids, batch, levels, learned)
        return states

    def _slacks(self) -> FloatArray:
        """Each pair's slack [m]: :data:`SLACK_SHARE` of its median distance over :data:`PROBES`."""
        probes = sampled_configurations(self.model, PROBES, np.random.default_rng(0))
        data, geometry_data = self.model.createData(), self.geometry_model.createData()
        distances = np.empty((len(probes), len(self.geometry_model.collisionPairs)))
        for n, q in enumerate(probes):
            pin.computeDistances(self.model, data, self.geometry_model, geometry_data, q)
            distances[n] = [result.min_distance for result in geometry_data.distanceResults]
        return np.clip(SLACK_SHARE * finite_median(distances, axis=0), MIN_SLACK_M, MAX_SLACK_M)

    def _level(self, margins_m: tuple[float, ...]) -> Float32Array:
        """The margins, coal's error added, rounded up to :data:`LEVEL_M`: float32 no smaller than them."""
        if margins_m not in self._levels:
            wanted = [m + float(coal_error_m(m)) for m in margins_m]
            rounded = [max(math.ceil(m / LEVEL_M) * LEVEL_M, m) for m in wanted]
            self._levels[margins_m] = np.array([_float32_at_least(m) for m in rounded])
        return self._levels[margins_m]

    def _states(
        self, grids: CellGrids, batch: FloatArray, levels: Float32Array, learned: LearnedCells
    ) -> tuple[IntArray, NDArray[np.int8]]:
        """:func:`cell_states` at ``levels`` ``(K,)`` [m]: cells ``(N, K)`` and states ``(N,)``."""
        cells = np.empty((len(batch), len(levels)), dtype=np.int64)
        states = np.empty(len(batch), dtype=np.int8)
        known = (learned.cleared, learned.refused, learned.centre_m)
        cell_states(np.ascontiguousarray(batch), *grids.arrays(), *known, levels, cells, states)
        return cells, states

    def _test(
        self, grids: CellGrids, k: int, level_m: float, cells: IntArray, rows: FloatArray, on_meshes: bool
    ) -> None:
        """Test pair ``k``'s ``cells`` (placed as ``rows``) at their centres, first above ``level_m`` [m]."""
        start = time.perf_counter()
        learned = self._learned[on_meshes]
        distinct, first = np.unique(cells, return_index=True)
        centres = grids.centres(k, distinct, rows[first])
        above = level_m + TESTED_ABOVE_M
        hit = self._hits(k, above + float(grids.slack_m[k]), centres, on_meshes)
        learned.cleared[distinct[~hit]] = _float32_at_most(above)
        if hit.any():
            refused = np.minimum(learned.refused[distinct[hit]], _float32_at_least(above))
            learned.refused[distinct[hit]] = refused
            slack_m = float(grids.slack_m[k])
            distinct, centres = distinct[hit], centres[hit]
            hit = self._hits(k, level_m + slack_m, centres, on_meshes)
            learned.cleared[distinct[~hit]] = _float32_at_most(level_m)
            learned.refused[distinct[hit]] = _float32_at_least(level_m)
            unmeasured = hit & np.isneginf(learned.centre_m[distinct])
            if unmeasured.any():  # a configuration near the centre may still clear the margin
                measured = self._centre_distances(k, centres[unmeasured], on_meshes)
                learned.centre_m[distinct[unmeasured]] = [_float32_at_most(d) for d in measured.tolist()]
        self.memory.learned(time.perf_counter() - start)

    def _centre_distances(self, k: int, centres: FloatArray, on_meshes: bool) -> FloatArray:
        """``(M,)`` lower bounds [m] of pair ``k``'s distance at ``centres``: coal's, less its error.

        On the hulls; ``on_meshes``, on the pair's meshes where it has one.
        """
        data = (self.model, self._data, self.geometry_model, self._geometry_data)
        unbounded, pair = np.full((len(centres), 1), -np.inf), np.array([k], dtype=np.int64)
        found, _ = closest_pairs(*data, centres, unbounded, pair, exact=self._exact if on_meshes else None)
        return found - coal_error_m(found)

    def _hits(self, k: int, margin_m: float, centres: FloatArray, on_meshes: bool) -> BoolArray:
        """``(M,)`` whether pair ``k`` may be within ``margin_m`` [m] (coal's error added) at ``centres``.

        On the hulls; ``on_meshes``, a hit on the hulls of a pair with an exact mesh is decided
        again on the meshes.
        """
        margin_m += float(coal_error_m(margin_m))
        key = (k, margin_m)
        if key not in self._pools:  # a few per pair: a plan asks a few margins
            if len(self._pools) >= MAX_POOLS:
                self._pools.clear()
            self._pools[key] = pin.GeometryPool(self.model, self.geometry_model, 1)
            active = np.arange(len(self.geometry_model.collisionPairs)) == k
            configure_pool(self._pools[key], self.geometry_model, margin_m, active)
        self.tested += len(centres)
        hit = pool_collisions(self._pools[key], self.model, self._data, self.geometry_model, centres, 1)
        if on_meshes and self._exact.refined[k] and hit.any():
            data = (self.model, self._data, self.geometry_model, self._geometry_data)
            hit[hit] = self._exact.violated(*data, centres[hit], [k], margin_m)
        return hit


def _with_pairs(collision_model: Any, pairs: Sequence[tuple[int, int]]) -> Any:
    """A copy of ``collision_model`` whose collision pairs are ``pairs``, in order (the model unchanged)."""
    geometry_model = collision_model.copy()
    geometry_model.removeAllCollisionPairs()
    for a, b in pairs:
        geometry_model.addCollisionPair(pin.CollisionPair(a, b))
    return geometry_model


def _float32_at_least(value: float) -> np.float32:
    """The least float32 >= ``value``."""
    rounded = np.float32(value)
    return rounded if rounded >= value else np.nextafter(rounded, np.float32(np.inf))


def _float32_at_most(value: float) -> np.float32:
    """The largest float32 <= ``value``."""
    rounded = np.float32(value)
    return rounded if rounded <= value else np.nextafter(rounded, np.float32(-np.inf))
