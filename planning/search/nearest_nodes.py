"""The node of a growing tree nearest a configuration: a k-d tree over most nodes, a scan of the newest.

RRT-Connect (:mod:`planning.search.rrt_connect`) asks twice a sample for the node of a tree
nearest a configuration, by the motion bound ``sum_j w_j |dq_j|``. A scan of every node costs
what the tree holds: on a hard problem (MotionBenchMaker's Fetch among shelves) the trees
reach tens of thousands of nodes, and the scans a large share of the plan (``docs/tuning.md``).

So a tree of :data:`INDEXED_FROM` nodes or more keeps them in a k-d tree
(:class:`NodeIndex`): cells of at most :data:`LEAF_NODES` nodes, each split at the median
along its widest extent (in the weights' units), each cell's box kept for the bound. It is
built again once the nodes added since reach :data:`REBUILD_SHARE` of those in it; the newest
are scanned. The search visits the cells nearest first and leaves those whose box is farther
than the nearest node found.

The answer is the scan's to the bit: the first node (lowest index) of least distance, each
distance summed joint by joint in order. A cell's bound sums, in the same order, terms each at
most the matching term of any of its nodes' distances (rounding is monotone), so it never
exceeds a distance computed there; a cell is left only where its bound is larger than the
best distance, so a tie with a lower index is never missed.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

INDEXED_FROM = 2048
"""Nodes from which a tree keeps its k-d tree: below, a scan is the cheaper (``docs/tuning.md``)."""
LEAF_NODES = 16
"""Most nodes of a cell of the k-d tree."""
REBUILD_SHARE = 0.125
"""The k-d tree is built again once the nodes added since reach this share of those in it."""


class NodeIndex:
    """The nodes ``nodes[:size]`` of a tree in a k-d tree, split along the extents weighed by ``weights``.

    Args:
        nodes: ``(N, d)`` the tree's nodes (rows beyond ``size`` unused).
        size: the nodes indexed, from the first.
        weights: ``(d,)`` each joint's weight of the distance (the splits follow it).
    """

    def __init__(self, nodes: FloatArray, size: int, weights: FloatArray) -> None:
        self.size = size
        self._cells = build_cells(nodes, size, np.asarray(weights, dtype=float), LEAF_NODES)

    def stale(self, size: int) -> bool:
        """Whether a tree of ``size`` nodes should build its index again (module docstring)."""
        return size - self.size >= REBUILD_SHARE * self.size

    def nearest(self, nodes: FloatArray, size: int, q: FloatArray, weights: FloatArray) -> int:
        """Index of the first of ``nodes[:size]`` nearest ``q`` (those beyond the index scanned)."""
        return nearest_indexed(nodes, size, self.size, q, weights, self._cells)


@njit
def build_cells(
    nodes: FloatArray, size: int, weights: FloatArray, leaf: int
) -> tuple[IntArray, FloatArray, FloatArray, IntArray, IntArray, IntArray]:
    """The k-d tree of ``nodes[:size]``: node order, and per cell its box, children and nodes' range.

    Returns ``(order, low, high, first_child, start, end)``: the nodes' indices ordered cell by
    cell; each cell's box ``low``, ``high`` ``(C, d)``; its first child (the second follows it;
    ``-1``: a leaf); and the range ``order[start:end]`` of its nodes. Cell 0 holds them all.
    """
    d = nodes.shape[1]
    cells = 4 * (size // leaf + 1) + 1  # a split cell holds more than leaf nodes: each leaf at least half
    order = np.arange(size)
    low, high = np.empty((cells, d)), np.empty((cells, d))
    first_child = np.full(cells, -1)
    start, end = np.zeros(cells, dtype=np.int64), np.zeros(cells, dtype=np.int64)
    start[0], end[0] = 0, size
    count, cell = 1, 0
    while cell < count:  # cells in the order they were made: each made before its children
        a, b = start[cell], end[cell]
        for j in range(d):
            low[cell, j], high[cell, j] = np.inf, -np.inf
        for k in range(a, b):
            i = order[k]
            for j in range(d):
                low[cell, j] = min(low[cell, j], nodes[i, j])
                high[cell, j] = max(high[cell, j], nodes[i, j])
        widest, extent = 0, -1.0
        for j in range(d):
            spread = (high[cell, j] - low[cell, j]) * weights[j]
            if spread > extent:
                widest, extent = j, spread
        if b - a > leaf and extent > 0.0:
            members = order[a:b].copy()
            ranked = np.argsort(nodes[members, widest], kind="mergesort")
            order[a:b] = members[ranked]
            middle = (a + b) // 2
            first_child[cell] = count
            start[count], end[count] = a, middle
            start[count + 1], end[count + 1] = middle, b
            count += 2
        cell += 1
    return order, low[:count], high[:count], first_child[:count], start[:count], end[:count]


@njit_inline
def _distance(nodes: FloatArray, i: int, q: FloatArray, weights: FloatArray) -> float:
    """``sum_j w_j |nodes[i, j] - q_j|``, summed in the joints' order: the scan's and the index's."""
    distance = 0.0
    for j in range(len(q)):
        distance += abs(nodes[i, j] - q[j]) * weights[j]
    return distance


@njit
def nearest_node(nodes: FloatArray, size: int, q: FloatArray, weights: FloatArray) -> int:
    """The first of ``nodes[:size]`` nearest ``q`` by the motion bound ``sum_j w_j |dq_j|``, by a scan."""
    best, index = np.inf, 0
    for i in range(size):
        distance = _distance(nodes, i, q, weights)
        if distance < best:
            best, index = distance, i
    return index


@njit
def _box_bound(low: FloatArray, high: FloatArray, cell: int, q: FloatArray, weights: FloatArray) -> float:
    """A lower bound of the distance from ``q`` to every node in ``cell``'s box (module docstring)."""
    bound = 0.0
    for j in range(len(q)):
        gap = 0.0
        if q[j] < low[cell, j]:
            gap = low[cell, j] - q[j]
        elif q[j] > high[cell, j]:
            gap = q[j] - high[cell, j]
        bound += gap * weights[j]
    return bound


@njit
def nearest_indexed(
    nodes: FloatArray,
    size: int,
    indexed: int,
    q: FloatArray,
    weights: FloatArray,
    cells: tuple[IntArray, FloatArray, FloatArray, IntArray, IntArray, IntArray],
) -> int:
    """The first of ``nodes[:size]`` nearest ``q``: the first ``indexed`` by their k-d tree, then a scan."""
    order, low, high, first_child, start, end = cells
    best, index = np.inf, -1
    stack, bounds = np.empty(128, dtype=np.int64), np.empty(128)
    stack[0], bounds[0], top = 0, _box_bound(low, high, 0, q, weights), 1
    while top > 0:
        top -= 1
        cell = stack[top]
        if bounds[top] > best:
            continue
        child = first_child[cell]
        if child < 0:
            for k in range(start[cell], end[cell]):
                i = order[k]
                distance = _distance(nodes, i, q, weights)
                if distance < best or (distance == best and i < index):
                    best, index = distance, i
            continue
        near, far = _box_bound(low, high, child, q, weights), _box_bound(low, high, child + 1, q, weights)
        if near <= far:  # the nearer popped first
            stack[top], bounds[top], stack[top + 1], bounds[top + 1] = child + 1, far, child, near
        else:
            stack[top], bounds[top], stack[top + 1], bounds[top + 1] = child, near, child + 1, far
        top += 2
    for i in range(indexed, size):  # the newest: each after every indexed one, so a tie keeps the index's
        distance = _distance(nodes, i, q, weights)
        if distance < best:
            best, index = distance, i
    return max(index, 0)
