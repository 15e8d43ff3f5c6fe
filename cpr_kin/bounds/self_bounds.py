"""Cheap lower bounds of the distances between a robot's own link pairs, for many configurations.

The self-collision test (:meth:`cpr_kin.collision.self_collision.SelfCollision.violated`) asks coal
about every checked pair at every configuration; most pairs of a serial arm are far apart
most of the time. As for obstacles (:mod:`cpr_kin.bounds.pair_bounds`), each geometry is enclosed
in a capsule fixed to its joint (:func:`~cpr_kin.bounds.pair_bounds.bounding_capsule`), placed by
the compiled kinematic chain; a pair's capsules are first compared by their bounding
spheres, then by the exact distance between their segments less both radii, and where that
leaves the pair in doubt, by each geometry's box against the other's capsule
(:mod:`cpr_kin.bounds.joint_boxes`: a squat link's). Each is at
most coal's distance between the geometries, so a configuration whose every pair is bounded
above a margin keeps it for certain, and only the others go to coal
(:class:`cpr_kin.collision.self_screen.ScreenedSelfTest`).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, KinematicChain, place_capsules
from cpr_kin.bounds.joint_boxes import boxed_pair_bound, joint_boxes
from cpr_kin.bounds.pair_bounds import joint_capsules
from cpr_kin.bounds.segments import segment_distance
from cpr_kin.bounds.self_blocks import PairBlocks, blocks_below
from cpr_kin.common.compiled import njit

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
    boxes: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    pair_a: IntArray,
    pair_b: IntArray,
) -> None:
    """Write into ``out[n, p]`` a lower bound [m] of pair ``p``'s distance at ``q[n]``.

    A pair whose bounding spheres are more than ``threshold`` apart gets that sphere bound
    (cheaper, looser); the others the capsules' distance, and where that is at most a finite
    ``threshold``, the larger of it and each geometry's box to the other's capsule
    (:mod:`cpr_kin.bounds.joint_boxes`; ``boxes`` its :class:`JointBoxes`' arrays, by capsule
    slot): what a yes/no test asks. An infinite ``threshold`` gives every pair its capsules'
    distance, the cheapest value at every pair.
    """
    joints = len(chain[0])
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    world = np.empty((len(capsule_joint), 2, 3))
    scratch = np.empty((4, 3))
    for n in range(len(q)):
        place_capsules(q[n], chain, capsule_joint, capsule_ends, rotation, translation, scratch, world)
        for k in range(len(pair_a)):
            a, b = pair_a[k], pair_b[k]
            x = 0.5 * (world[a, 0, 0] + world[a, 1, 0] - world[b, 0, 0] - world[b, 1, 0])
            y = 0.5 * (world[a, 0, 1] + world[a, 1, 1] - world[b, 0, 1] - world[b, 1, 1])
            z = 0.5 * (world[a, 0, 2] + world[a, 1, 2] - world[b, 0, 2] - world[b, 1, 2])
            spheres = np.sqrt(x * x + y * y + z * z) - capsule_reach[a] - capsule_reach[b]
            if spheres > threshold:
                out[n, k] = spheres
                continue
            bound = segment_distance(world[a], world[b]) - capsule_radius[a] - capsule_radius[b]
            if threshold < np.inf:
                bound = boxed_pair_bound(
                    a, b, rotation, translation, boxes, world, capsule_radius, bound, threshold
                )
            out[n, k] = bound


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
        self._boxes = joint_boxes(collision_model, geometries)
        self._slot_pairs = [(slot[a], slot[b]) for a, b in pairs]  # capsule slots
        self._arguments: tuple[Any, ...] = (
            self._chain.arrays,
            *self._capsules,
            tuple(self._boxes),
            np.array([a for a, _ in self._slot_pairs], dtype=np.int64),
            np.array([b for _, b in self._slot_pairs], dtype=np.int64),
        )
        self.n_pairs = len(pairs)
        self._pair_arguments: dict[int, tuple[Any, ...]] = {}

    @functools.cached_property
    def _blocks(self) -> tuple[Any, ...]:
        """:func:`~cpr_kin.bounds.self_blocks.blocks_below`'s capsules and blocks, built on the first call."""
        return (
            tuple(self._capsules),
            tuple(self._boxes),
            PairBlocks.build(self._capsules, self._slot_pairs).arrays,
        )

    def __call__(self, q: FloatArray, threshold_m: float = np.inf) -> FloatArray:
        """``(N, P)`` lower bounds [m] of each pair's distance at configurations ``q`` ``(N, nq)``.

        Pairs whose bounding spheres are more than ``threshold_m`` apart get the spheres'
        bound; the others (all, by default) the capsules', and those within a finite
        ``threshold_m`` the boxes' too where larger (:func:`self_bounds`).
        """
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty((len(batch), self.n_pairs))
        self_bounds(batch, float(threshold_m), out, *self._arguments)
        return out

    def column(self, q: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` the capsules' lower bound [m] of the distance of pair ``pair`` (a column) alone.

        Only its two capsules are placed (:meth:`_one_pair`): a certified self check asks one
        pair at a time at many samples, and placing every capsule took most of its time.
        """
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty((len(batch), 1))
        self_bounds(batch, np.inf, out, self._arguments[0], *self._one_pair(pair))
        return out[:, 0]

    def _one_pair(self, pair: int) -> tuple[Any, ...]:
        """:func:`self_bounds`' capsule arguments of pair ``pair``'s two capsules alone, as pair 0-1."""
        if pair not in self._pair_arguments:
            _, joint, ends, radius, reach, _, pair_a, pair_b = self._arguments
            both = np.array([pair_a[pair], pair_b[pair]])
            first, second = np.zeros(1, dtype=np.int64), np.ones(1, dtype=np.int64)
            boxes = tuple(array[both] for array in self._boxes)
            capsules = (joint[both], ends[both], radius[both], reach[both])
            self._pair_arguments[pair] = (*capsules, boxes, first, second)
        return self._pair_arguments[pair]

    def any_below(self, q: FloatArray, threshold_m: float) -> BoolArray:
        """``(N,)`` whether some pair may be within ``threshold_m`` [m] at configurations ``q``.

        Whether some column of ``self(q, threshold_m)`` is at most ``threshold_m``, found by
        blocks of pairs (:mod:`cpr_kin.bounds.self_blocks`).
        """
        batch = np.ascontiguousarray(np.atleast_2d(q), dtype=float)
        out = np.empty(len(batch), dtype=bool)
        blocks_below(batch, float(threshold_m), out, self._chain.arrays, *self._blocks)
        return out


def bounded_pairs(
    model: Any, collision_model: Any, pairs: Sequence[tuple[int, int]], q: FloatArray, at_most_m: float
) -> tuple[list[tuple[int, int]], Any]:
    """The ``pairs`` bounded by at most ``at_most_m`` [m] at every configuration ``q``, and their model.

    The bound is their capsules'; a pair bounded above it somewhere is certainly farther
    there, and coal decides the others, in the copy of ``collision_model`` returned, holding
    them as its only collision pairs, in order.
    """
    bounds = SelfPairBounds(model, collision_model, pairs)(q)
    candidates = [
        pair for pair, below in zip(pairs, np.all(bounds <= at_most_m, axis=0), strict=True) if below
    ]
    geometry_model = collision_model.copy()
    geometry_model.removeAllCollisionPairs()
    for a, b in candidates:
        geometry_model.addCollisionPair(pin.CollisionPair(a, b))
    return candidates, geometry_model
