"""Cheap lower bounds of the distances between a robot's own link pairs, for many configurations.

The self-collision test (:meth:`cpr_kin.self_collision.SelfCollision.violated`) asks coal
about every checked pair at every configuration; most pairs of a serial arm are far apart
most of the time. As for obstacles (:mod:`cpr_kin.pair_bounds`), each geometry is enclosed
in a capsule fixed to its joint (:func:`~cpr_kin.pair_bounds.bounding_capsule`), placed by
the compiled kinematic chain; a pair's capsules are first compared by their bounding
spheres, then by the exact distance between their segments less both radii. Both are at
most coal's distance between the geometries, so a configuration whose every pair is bounded
above a margin keeps it for certain, and only the others go to coal.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.batch_kinematics import ChainArrays, KinematicChain, place_joints
from cpr_kin.closest_pairs import closest_pairs
from cpr_kin.compiled import njit
from cpr_kin.limits import sampled_configurations
from cpr_kin.obstacle_pools import configure_pool, pool_collisions
from cpr_kin.pair_bounds import BOUND_TOLERANCE_M, joint_capsules
from cpr_kin.segments import segment_distance
from cpr_kin.self_blocks import PairBlocks, blocks_below

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@njit
def self_bounds(
    q: FloatArray,
    threshold: float,
    out: FloatArray,
    chain: ChainArrays,
    capsule_joint: IntArray,
    capsule_ends: FloatArray,
    capsule_radius: FloatArray,
    capsule_reach: FloatArray,
    pair_a: IntArray,
    pair_b: IntArray,
) -> None:
    """Write into ``out[n, p]`` a lower bound [m] of pair ``p``'s distance at ``q[n]``.

    A pair whose bounding spheres are more than ``threshold`` apart gets that sphere bound
    (cheaper, looser); the others the capsules' distance.
    """
    joints = len(chain[0])
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    world = np.empty((len(capsule_joint), 2, 3))
    scratch = np.empty((4, 3))
    for n in range(len(q)):
        place_joints(q[n], chain, rotation, translation, scratch)
        for c in range(len(capsule_joint)):
            j = capsule_joint[c]
            for e in range(2):
                for r in range(3):
                    if j < 0:
                        world[c, e, r] = capsule_ends[c, e, r]
                    else:
                        world[c, e, r] = (
                            translation[j, r]
                            + rotation[j, r, 0] * capsule_ends[c, e, 0]
                            + rotation[j, r, 1] * capsule_ends[c, e, 1]
                            + rotation[j, r, 2] * capsule_ends[c, e, 2]
                        )
        for k in range(len(pair_a)):
            a, b = pair_a[k], pair_b[k]
            x = 0.5 * (world[a, 0, 0] + world[a, 1, 0] - world[b, 0, 0] - world[b, 1, 0])
            y = 0.5 * (world[a, 0, 1] + world[a, 1, 1] - world[b, 0, 1] - world[b, 1, 1])
            z = 0.5 * (world[a, 0, 2] + world[a, 1, 2] - world[b, 0, 2] - world[b, 1, 2])
            spheres = np.sqrt(x * x + y * y + z * z) - capsule_reach[a] - capsule_reach[b]
            if spheres > threshold:
                out[n, k] = spheres
            else:
                out[n, k] = segment_distance(world[a], world[b]) - capsule_radius[a] - capsule_radius[b]


class SelfPairBounds:
    """Lower bounds of a robot's own pair distances, for batches of configurations.

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: the robot's Pinocchio geometry model.
        pairs: ``(geometry index, geometry index)`` per output column.
    """

    def __init__(self, model: Any, collision_model: Any, pairs: Sequence[tuple[int, int]]) -> None:
        self._chain = KinematicChain.from_model(model)
        geometries = sorted({g for pair in pairs for g in pair})
        slot = {g: k for k, g in enumerate(geometries)}
        self._capsules = joint_capsules(collision_model, geometries)
        self._slot_pairs = [(slot[a], slot[b]) for a, b in pairs]  # capsule slots
        self._arguments: tuple[Any, ...] = (
            self._chain.arrays,
            *self._capsules,
            np.array([a for a, _ in self._slot_pairs], dtype=np.int64),
            np.array([b for _, b in self._slot_pairs], dtype=np.int64),
        )
        self.n_pairs = len(pairs)

    @functools.cached_property
    def _blocks(self) -> tuple[Any, ...]:
        """:func:`~cpr_kin.self_blocks.blocks_below`'s capsules and blocks, built on the first call."""
        return (tuple(self._capsules), PairBlocks.build(self._capsules, self._slot_pairs).arrays)

    def __call__(self, q: FloatArray, threshold_m: float = np.inf) -> FloatArray:
        """``(N, P)`` lower bounds [m] of each pair's distance at configurations ``q`` ``(N, nq)``.

        Pairs whose bounding spheres are more than ``threshold_m`` apart get the spheres'
        bound; the others (all, by default) the capsules'.
        """
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty((len(batch), self.n_pairs))
        self_bounds(batch, float(threshold_m), out, *self._arguments)
        return out

    def column(self, q: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` the capsules' lower bound [m] of the distance of pair ``pair`` (a column) alone."""
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty((len(batch), 1))
        chain, joint, ends, radius, reach, pair_a, pair_b = self._arguments
        one = slice(pair, pair + 1)
        self_bounds(batch, np.inf, out, chain, joint, ends, radius, reach, pair_a[one], pair_b[one])
        return out[:, 0]

    def any_below(self, q: FloatArray, threshold_m: float) -> BoolArray:
        """``(N,)`` whether some pair may be within ``threshold_m`` [m] at configurations ``q``.

        Whether some column of ``self(q, threshold_m)`` is at most ``threshold_m``, found by
        blocks of pairs (:mod:`cpr_kin.self_blocks`).
        """
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty(len(batch), dtype=bool)
        blocks_below(batch, float(threshold_m), out, self._chain.arrays, *self._blocks)
        return out


PROBES = 256
"""Random configurations on which :class:`ScreenedSelfTest` finds the pairs that are always near."""
NEAR_SHARE = 0.5
"""Share of those in which a pair's bound is uncertain that makes it a near pair."""
PROBE_THRESHOLD_M = 0.05
"""The distance [m] the probes ask the bounds about (a typical margin and more)."""


class ScreenedSelfTest:
    """coal's yes/no self-collision test, screened by the pairs' bounds (module docstring).

    Some pairs of a serial arm are always close (a link and the one two joints down its
    chain, a few centimetres apart by design): bounding them first would only delay coal.
    So the pairs are split once, on :data:`PROBES` seeded random configurations within the
    joint ranges: those whose bound is uncertain in more than :data:`NEAR_SHARE` of them
    (*near*) go to coal at every configuration, the others (*far*) only at configurations
    where some far pair's bound is within the margin, and there only the far pairs whose
    bounds are within it in some configuration of the batch (a few of a thousand pairs on an
    arm whose hand has a dozen links). Each group has its own Pinocchio ``GeometryPool``, run
    in parallel over ``num_threads`` threads, stopping at a configuration's first hit. The
    answer is coal's on every pair.

    A pair's distance counts its allowance (:mod:`cpr_kin.close_pairs`): coal's distance plus
    ``allowance_m``, so a margin asks coal for that much less of the pair (never below contact).

    Args:
        model: the robot's Pinocchio model.
        geometry_model: its geometry model with the pairs added, in order.
        pairs: the pairs' geometry indices.
        num_threads: threads of coal's batches.
        allowance_m: ``(P,)`` each pair's allowance [m] (default: none).
    """

    def __init__(
        self,
        model: Any,
        geometry_model: Any,
        pairs: Sequence[tuple[int, int]],
        num_threads: int,
        allowance_m: FloatArray | None = None,
    ) -> None:
        self.model, self.geometry_model, self.num_threads = model, geometry_model, num_threads
        self.allowance_m = (
            np.zeros(len(pairs)) if allowance_m is None else np.asarray(allowance_m, dtype=float)
        )
        probes = sampled_configurations(model, PROBES, np.random.default_rng(0))
        self.all_bounds = SelfPairBounds(model, geometry_model, pairs)
        uncertain = self.all_bounds(probes, PROBE_THRESHOLD_M) <= PROBE_THRESHOLD_M
        near = uncertain.mean(axis=0) > NEAR_SHARE
        self.near_pairs = tuple(p for p, is_near in zip(pairs, near, strict=True) if is_near)
        self.far_bounds = SelfPairBounds(
            model, geometry_model, [p for p, n in zip(pairs, near, strict=True) if not n]
        )
        self._near = near
        self._far_index = np.flatnonzero(~near)
        self._far_on = np.zeros(len(pairs), dtype=bool)  # the far pool's active pairs
        self._pools: list[Any] = []
        self._data: Any = None
        self._distance_data: Any = None
        self._margin_m = float("nan")

    def violated(self, batch: FloatArray, margin_m: float) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``batch``."""
        self._prepare(margin_m)
        hits = np.zeros(len(batch), dtype=bool)
        if self.near_pairs:
            hits[:] = self._coal(0, batch)
        if self.far_bounds.n_pairs:
            open_rows = np.flatnonzero(~hits)
            threshold = margin_m + BOUND_TOLERANCE_M
            doubtful = open_rows[self.far_bounds.any_below(batch[open_rows], threshold)]
            if doubtful.size:
                within = self.far_bounds(batch[doubtful], threshold) <= threshold
                self._switch_far(np.any(within, axis=0))
                hits[doubtful] = self._coal(1, batch[doubtful])
        return hits

    def _switch_far(self, doubtful: BoolArray) -> None:
        """Make the far pool test only the far pairs ``doubtful`` ``(P_far,)``: the rest clear the margin."""
        wanted = np.zeros_like(self._far_on)
        wanted[self._far_index[doubtful]] = True
        changed = np.flatnonzero(wanted != self._far_on).tolist()
        for gdata in self._pools[1].getGeometryDatas():
            for p in changed:
                (gdata.activateCollisionPair if wanted[p] else gdata.deactivateCollisionPair)(p)
        self._far_on = wanted

    def distances(self, batch: FloatArray) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair (index among all pairs), ``(N,)`` each, exactly.

        coal's distance of the closest pair, the pairs visited in the order of their bounds
        until no pair left can be closer (:func:`cpr_kin.closest_pairs.closest_pairs`).
        """
        bounds = self.bounds(batch)
        return self._closest(batch, bounds, np.arange(bounds.shape[1]))

    def bounds(self, batch: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of every pair's distance (its capsules') at ``batch``."""
        return self.all_bounds(batch) + self.allowance_m

    def pair_bounds(self, batch: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` lower bounds [m] of pair ``pair``'s distance (its capsules') at ``batch``."""
        return self.all_bounds.column(batch, pair) + float(self.allowance_m[pair])

    def pair_distances(self, batch: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` coal's distance [m] of pair ``pair`` (index among all pairs) at ``batch``."""
        return self._closest(batch, np.full((len(batch), 1), -np.inf), np.array([pair], dtype=np.int64))[0]

    def _closest(self, batch: FloatArray, bounds: FloatArray, pairs: IntArray) -> tuple[FloatArray, IntArray]:
        """:func:`~cpr_kin.closest_pairs.closest_pairs` of ``pairs`` (bounded by ``bounds``) at ``batch``."""
        self._prepare(float("nan"))
        data = (self.model, self._data, self.geometry_model, self._distance_data)
        return closest_pairs(*data, batch, bounds, pairs, offsets_m=self.allowance_m[pairs])

    def _coal(self, tier: int, batch: FloatArray) -> NDArray[np.bool_]:
        """Coal's test of the pairs of ``tier`` (0 near, 1 far) at configurations ``batch``."""
        return pool_collisions(
            self._pools[tier], self.model, self._data, self.geometry_model, batch, self.num_threads
        )

    def _prepare(self, margin_m: float) -> None:
        """Build the two pools and distance data once; set their margin and pairs when the margin changes.

        A NaN ``margin_m`` leaves the margin as it is.
        """
        if not self._pools:
            self._data = self.model.createData()
            self._distance_data = self.geometry_model.createData()
            self._pools = [
                pin.GeometryPool(self.model, self.geometry_model, self.num_threads) for _ in range(2)
            ]
        if margin_m != self._margin_m and not np.isnan(margin_m):
            margins = np.maximum(margin_m - self.allowance_m, 0.0) if self.allowance_m.any() else margin_m
            for pool, active in zip(self._pools, (self._near, self._far_on), strict=True):
                configure_pool(pool, self.geometry_model, margins, active)
                for gdata in pool.getGeometryDatas():
                    for request in gdata.collisionRequests:
                        request.enable_contact = False
            self._margin_m = margin_m
