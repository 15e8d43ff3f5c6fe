"""Robot-obstacle pairs in blocks: one capsule against a cluster of nearby obstacles.

The margin test's first step (:func:`~cpr_kin.bounds.bound_kernels.groups_below`) asks of
every robot capsule and obstacle whether the capsule's bounding sphere comes within the margin
of the box, in the world's axes, that holds the obstacle. Most pairs fail at once, but an arm
among shelves has 100-300 pairs, and at a few nanoseconds each that loop was a third of the
test's time on the UR5 (``docs/tuning.md``, Kernels). Here the obstacles are split into
clusters of a few neighbours (halved at the median of their centres along the widest axis,
recursively) and each capsule's pairs are grouped by cluster: a block. A block whose cluster's
box (the union of its obstacles' boxes) is farther from the capsule's sphere than the margin
along some axis holds no pair that passes that test, and is skipped whole.

The skip is the pairs' own first test applied to a larger box, so it skips only pairs that
test would skip: the answers are the same, bit for bit (:data:`BOX_PADDING_M` covers rounding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.arrays import distinct_sorted

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

CLUSTER_SIZE = 4
"""Most obstacles in a cluster: halved until no more (``docs/tuning.md``, Kernels)."""
BOX_PADDING_M = 1e-9
"""A cluster's box grown by this much [m]: a block is skipped only where every pair's own test
(computed from the obstacle's centre, so rounded differently) would skip too."""


@dataclass(frozen=True)
class ObstacleBlocks:
    """The pairs of a set, ordered by block (the compiled kernels' arguments, :attr:`arrays`).

    Attributes:
        capsule: ``(B,)`` each block's capsule (the pairs' capsule slot).
        box: ``(B, 2, 3)`` the least and greatest corner of its cluster's box in the world [m],
            grown by :data:`BOX_PADDING_M`.
        start: ``(B + 1,)`` where each block's pairs begin in :attr:`order` (and where the
            last ends).
        order: ``(P,)`` the pairs' indices, block by block.
    """

    capsule: IntArray
    box: FloatArray
    start: IntArray
    order: IntArray

    @property
    def arrays(self) -> tuple[IntArray, FloatArray, IntArray, IntArray]:
        """The fields, in order, as compiled code takes them."""
        return self.capsule, self.box, self.start, self.order


def obstacle_blocks(
    pair_capsule: IntArray,
    pair_obstacle: IntArray,
    centre: FloatArray,
    extent: FloatArray,
    cluster_size: int = CLUSTER_SIZE,
) -> ObstacleBlocks:
    """The blocks of pairs ``(pair_capsule[p], pair_obstacle[p])`` (module docstring).

    Args:
        pair_capsule: ``(P,)`` each pair's capsule.
        pair_obstacle: ``(P,)`` each pair's obstacle, a row of ``centre`` and ``extent``.
        centre: ``(O, 3)`` the obstacles' centres in the world [m].
        extent: ``(O, 3)`` the half sides of a box in the world's axes about each centre that
            holds its obstacle [m].
        cluster_size: most obstacles in a cluster, >= 1.
    """
    if not len(pair_capsule):
        return ObstacleBlocks(
            np.zeros(0, np.int64), np.zeros((0, 2, 3)), np.zeros(1, np.int64), np.zeros(0, np.int64)
        )
    used = distinct_sorted(pair_obstacle)  # np.unique would import numpy.ma into a new process
    cluster = np.empty(len(centre), dtype=np.int64)
    boxes = []
    for k, members in enumerate(_clusters(centre, used, cluster_size)):
        cluster[members] = k
        low = (centre[members] - extent[members]).min(axis=0) - BOX_PADDING_M
        high = (centre[members] + extent[members]).max(axis=0) + BOX_PADDING_M
        boxes.append((low, high))
    pair_cluster = cluster[pair_obstacle]
    order = np.lexsort((np.arange(len(pair_capsule)), pair_cluster, pair_capsule)).astype(np.int64)
    key = np.stack([pair_capsule[order], pair_cluster[order]], axis=1)
    first = np.flatnonzero(np.r_[True, np.any(key[1:] != key[:-1], axis=1)])
    box = np.array([boxes[c] for c in key[first, 1]], dtype=float).reshape(-1, 2, 3)
    return ObstacleBlocks(
        key[first, 0].astype(np.int64), box, np.r_[first, len(order)].astype(np.int64), order
    )


def _clusters(centre: FloatArray, members: IntArray, size: int) -> list[IntArray]:
    """``members`` (obstacle rows) in clusters of at most ``size``: halved at the widest axis's median."""
    if len(members) <= size:
        return [members]
    points = centre[members]
    axis = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
    ordered = members[np.argsort(points[:, axis], kind="stable")]
    half = len(ordered) // 2
    return _clusters(centre, ordered[:half], size) + _clusters(centre, ordered[half:], size)
