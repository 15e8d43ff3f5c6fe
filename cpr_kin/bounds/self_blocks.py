"""Whether any of a robot's own link pairs may be within a distance, pairs screened in blocks.

A humanoid's or a dual arm's hand carries a dozen finger links, each paired with every link
of the body and upper arm: a few hundred pairs, most of them far apart, each compared by its
bounding spheres at every configuration (:func:`cpr_kin.bounds.self_bounds.self_bounds`). Here the
capsules of each joint (the world's too) are split into clusters of at most
:data:`CLUSTER_RADIUS_M` (a hand's links, a stretch of the torso), each enclosed in a sphere
fixed to its joint, and the pairs are grouped in *blocks* by the clusters of their two
capsules. Where a block's two spheres are more than the threshold apart, so is every pair of
the block, and none of them is looked at; the others are bounded pair by pair as in
:func:`~cpr_kin.bounds.self_bounds.self_bounds`, and a configuration stops at its first pair within
the threshold. The answer is the pair-by-pair bounds' (:meth:`SelfPairBounds.any_below
<cpr_kin.bounds.self_bounds.SelfPairBounds.any_below>`), only cheaper.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, place_capsule, place_joints
from cpr_kin.bounds.joint_boxes import boxed_pair_bound
from cpr_kin.bounds.pair_bounds import JointCapsules
from cpr_kin.bounds.segments import segment_distance
from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


CLUSTER_RADIUS_M = 0.25
"""Largest radius [m] of a cluster of capsules on one joint, unless it holds a single capsule."""


@dataclass(frozen=True)
class PairBlocks:
    """Pairs grouped by the clusters of their two capsules.

    The capsules of each joint (-1: fixed to the world) are split into clusters, each within
    a sphere of radius ``radius[m]`` [m] about ``centre[m]`` in ``joint[m]``'s frame.
    Block ``k`` holds the pairs ``pair_a[start[k]:start[k + 1]]`` / ``pair_b[...]``
    (capsule slots) between clusters ``block_a[k]`` and ``block_b[k]``.
    """

    joint: IntArray
    centre: FloatArray
    radius: FloatArray
    block_a: IntArray
    block_b: IntArray
    start: IntArray
    pair_a: IntArray
    pair_b: IntArray

    @property
    def arrays(
        self,
    ) -> tuple[IntArray, FloatArray, FloatArray, IntArray, IntArray, IntArray, IntArray, IntArray]:
        """The fields, in order, as :func:`blocks_below` takes them."""
        return (
            self.joint,
            self.centre,
            self.radius,
            self.block_a,
            self.block_b,
            self.start,
            self.pair_a,
            self.pair_b,
        )

    @classmethod
    def build(cls, capsules: JointCapsules, pairs: Sequence[tuple[int, int]]) -> PairBlocks:
        """Blocks of ``pairs`` (capsule slots of ``capsules``), each pair in one block."""
        slots = sorted({s for pair in pairs for s in pair})
        clusters: list[tuple[list[int], FloatArray, float]] = []  # members, centre, radius
        for joint in sorted({int(capsules.joint[s]) for s in slots}):
            clusters += _split(capsules, [s for s in slots if capsules.joint[s] == joint])
        cluster_of = {s: m for m, (members, _, _) in enumerate(clusters) for s in members}
        members_of: dict[tuple[int, int], list[tuple[int, int]]] = {}
        for a, b in pairs:
            key = (cluster_of[a], cluster_of[b])
            members_of.setdefault(key, []).append((a, b))
        ordered = [pair for block in members_of.values() for pair in block]
        return cls(
            np.array([capsules.joint[members[0]] for members, _, _ in clusters], dtype=np.int64),
            np.array([centre for _, centre, _ in clusters], dtype=float).reshape(-1, 3),
            np.array([radius for _, _, radius in clusters], dtype=float),
            np.array([a for a, _ in members_of], dtype=np.int64),
            np.array([b for _, b in members_of], dtype=np.int64),
            np.cumsum([0] + [len(block) for block in members_of.values()], dtype=np.int64),
            np.array([a for a, _ in ordered], dtype=np.int64),
            np.array([b for _, b in ordered], dtype=np.int64),
        )


def _split(capsules: JointCapsules, slots: list[int]) -> list[tuple[list[int], FloatArray, float]]:
    """``slots`` (capsules on one joint) in clusters within :data:`CLUSTER_RADIUS_M` or of one capsule.

    Each cluster with its enclosing sphere (:func:`_enclosing_sphere`). Halved recursively
    at the median of the capsules' middles along their widest axis.
    """
    centre, radius = _enclosing_sphere(capsules, slots)
    if radius <= CLUSTER_RADIUS_M or len(slots) == 1:
        return [(slots, centre, radius)]
    middles = capsules.ends[slots].mean(axis=1)
    axis = int(np.argmax(middles.max(axis=0) - middles.min(axis=0)))
    order = [slots[i] for i in np.argsort(middles[:, axis], kind="stable")]
    half = len(order) // 2
    return _split(capsules, order[:half]) + _split(capsules, order[half:])


def _enclosing_sphere(capsules: JointCapsules, slots: Sequence[int]) -> tuple[FloatArray, float]:
    """A sphere (centre in the slots' joint frame [m], radius [m]) enclosing capsules ``slots``.

    Centred on the middle of the capsules' end points' bounding box (not the smallest such
    sphere); each capsule lies within its reach of its middle.
    """
    chosen = list(slots)
    ends = capsules.ends[chosen].reshape(-1, 3)
    centre = (ends.min(axis=0) + ends.max(axis=0)) / 2
    middles = capsules.ends[chosen].mean(axis=1)
    radius = np.linalg.norm(middles - centre, axis=1) + capsules.reach[chosen]
    return centre, float(radius.max())


@njit
def blocks_below(
    q: FloatArray,
    threshold: float,
    out: BoolArray,
    chain: ChainArrays,
    capsules: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    boxes: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    blocks: tuple[IntArray, FloatArray, FloatArray, IntArray, IntArray, IntArray, IntArray, IntArray],
) -> None:
    """Write into ``out[n]`` whether some pair's bound is at most ``threshold`` [m] at ``q[n]``.

    ``capsules`` holds :class:`~cpr_kin.bounds.pair_bounds.JointCapsules`' arrays, ``boxes``
    :class:`~cpr_kin.bounds.joint_boxes.JointBoxes`' (a pair the capsules leave within the
    threshold is then bounded by each geometry's box as well), ``blocks``
    :class:`PairBlocks`' (module docstring). Each configuration places the capsules'
    middles and the clusters' centres; a capsule's ends only once a pair needs its segment.
    Points fixed to the world are placed once. Scalar code with explicit indices: compiled
    helpers taking array views ran twice as slow.
    """
    capsule_joint, capsule_ends, capsule_radius, capsule_reach = capsules
    cluster_joint, centre, cluster_radius, block_a, block_b, start, pair_a, pair_b = blocks
    joints, capsule_count = len(chain[0]), len(capsule_joint)
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    # rows [0, C): the capsules' middles; rows [C, C + M): the clusters' centres
    local = np.empty((capsule_count + len(cluster_joint), 3))
    joint = np.concatenate((capsule_joint, cluster_joint))
    for c in range(capsule_count):
        for r in range(3):
            local[c, r] = 0.5 * (capsule_ends[c, 0, r] + capsule_ends[c, 1, r])
    local[capsule_count:] = centre
    point = local.copy()  # fixed points stay as they are
    world = capsule_ends.copy()
    placed = capsule_joint < 0
    scratch = np.empty((4, 3))
    for n in range(len(q)):
        out[n] = False
        place_joints(q[n], chain, rotation, translation, scratch)
        for i in range(len(joint)):
            j = joint[i]
            if j >= 0:
                for r in range(3):
                    point[i, r] = (
                        translation[j, r]
                        + rotation[j, r, 0] * local[i, 0]
                        + rotation[j, r, 1] * local[i, 1]
                        + rotation[j, r, 2] * local[i, 2]
                    )
        for c in range(capsule_count):
            placed[c] = capsule_joint[c] < 0
        for k in range(len(block_a)):
            if start[k + 1] - start[k] > 1:
                i, m = capsule_count + block_a[k], capsule_count + block_b[k]
                x, y, z = point[i, 0] - point[m, 0], point[i, 1] - point[m, 1], point[i, 2] - point[m, 2]
                gap = np.sqrt(x * x + y * y + z * z) - cluster_radius[block_a[k]] - cluster_radius[block_b[k]]
                if gap > threshold:
                    continue
            for p in range(start[k], start[k + 1]):
                a, b = pair_a[p], pair_b[p]
                x, y, z = point[a, 0] - point[b, 0], point[a, 1] - point[b, 1], point[a, 2] - point[b, 2]
                if np.sqrt(x * x + y * y + z * z) - capsule_reach[a] - capsule_reach[b] > threshold:
                    continue
                for c in (a, b):
                    if not placed[c]:
                        placed[c] = True
                        place_capsule(c, rotation, translation, capsule_joint, capsule_ends, world)
                bound = segment_distance(world[a], world[b]) - capsule_radius[a] - capsule_radius[b]
                bound = boxed_pair_bound(
                    a, b, rotation, translation, boxes, world, capsule_radius, bound, threshold
                )
                if bound <= threshold:
                    out[n] = True
                    break
            if out[n]:
                break
