"""RRT-Connect's trees (:mod:`planning.search.rrt_connect`): grown towards samples, joined, and kept.

:class:`Sampler` draws the samples a tree grows towards and :func:`connect` grows one greedily
along a checked way.

A robot with exact link meshes is planned on their convex hulls first
(:mod:`planning.pipeline.hulls_first`): RRT-Connect's trees grow there under a validity stricter
than the meshes', since every configuration and edge clear of the hulls is clear of the
meshes they contain. When the hulls' draw ends without a path (its share of the samples or
of a time limit spent), the meshes' draw between the same ends goes on growing its trees
(:class:`GrownTrees`) rather than growing new ones from its ends: nothing the hulls found is
drawn again.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from planning.search.nearest_nodes import INDEXED_FROM, NodeIndex, nearest_node
from planning.search.rrt_settings import RrtSettings

FloatArray = NDArray[np.float64]


class Tree:
    """Nodes and parents, grown in place (arrays doubled when full)."""

    def __init__(self, root: FloatArray) -> None:
        self.nodes = np.empty((64, root.size))
        self.parents = np.empty(64, dtype=np.intp)
        self.nodes[0], self.parents[0], self.size = root, -1, 1
        self._index: NodeIndex | None = None

    def add(self, q: FloatArray, parent: int) -> int:
        """Add node ``q`` under node ``parent``; its index."""
        if self.size == len(self.nodes):
            self.nodes = np.concatenate([self.nodes, np.empty_like(self.nodes)])
            self.parents = np.concatenate([self.parents, np.empty_like(self.parents)])
        self.nodes[self.size], self.parents[self.size] = q, parent
        self.size += 1
        return self.size - 1

    def nearest(self, q: FloatArray, weights: FloatArray) -> int:
        """Index of the first node nearest to ``q`` by the motion bound with ``weights``.

        A scan of every node, or from :data:`~planning.search.nearest_nodes.INDEXED_FROM` nodes
        on, a k-d tree of them (:mod:`planning.search.nearest_nodes`): the same node.
        """
        if self.size < INDEXED_FROM:
            return nearest_node(self.nodes, self.size, q, weights)
        if self._index is None or self._index.stale(self.size):
            self._index = NodeIndex(self.nodes, self.size, weights)
        return self._index.nearest(self.nodes, self.size, q, weights)

    def branch(self, index: int) -> FloatArray:
        """The nodes from ``index`` back to the root."""
        chain = []
        while index >= 0:
            chain.append(self.nodes[index])
            index = int(self.parents[index])
        return np.array(chain)


class GrownTrees:
    """Where a draw that found no path leaves its two trees, for the next draw between the same ends.

    :func:`~planning.search.rrt_connect.rrt_connect` given one starts from the trees kept here
    (and takes them: a draw that finds a path leaves none) where they grew between the same
    start and goal, their edges checked at the same spacing; trees that grew on under a
    relaxation (:class:`~planning.search.rrt_connect.Relaxation`) are taken only by a draw
    with one, which goes on under it at once. Its caller promises that the draw's validity
    accepts every configuration the earlier draw's did, and its relaxation the earlier
    relaxation's (the meshes after their hulls, at the same clearances), or gives ``agree``:
    asked only when there are trees to take, it says whether that promise holds (a check that
    costs queries no plan whose first draw finds its path should pay). A draw that ends
    without a path keeps its trees here.
    """

    def __init__(self, agree: Callable[[], bool] | None = None) -> None:
        self._trees: tuple[Tree, Tree] | None = None
        self._key: tuple[bytes, bytes, float] | None = None
        self._agree = agree
        self.relaxed = False

    def take(
        self, start: FloatArray, goal: FloatArray, resolution_m: float, relaxable: bool
    ) -> tuple[Tree, Tree] | None:
        """The trees kept between ``start`` and ``goal`` at edge spacing ``resolution_m`` [m], or ``None``.

        ``relaxable``: the draw has a relaxation to go on under (else trees kept relaxed are
        not taken). :attr:`relaxed` then says whether they grew under one.
        """
        trees, key = self._trees, self._key
        self._trees = self._key = None
        if key != _key(start, goal, resolution_m) or (self.relaxed and not relaxable):
            return None
        return trees if self._agree is None or self._agree() else None

    def keep(
        self,
        trees: tuple[Tree, Tree],
        start: FloatArray,
        goal: FloatArray,
        resolution_m: float,
        relaxed: bool,
    ) -> None:
        """Keep ``trees`` grown from ``start`` and ``goal``, edges every ``resolution_m`` [m]."""
        self._trees, self._key, self.relaxed = trees, _key(start, goal, resolution_m), relaxed

    @property
    def nodes(self) -> int:
        """The nodes of the trees kept (0: none)."""
        return 0 if self._trees is None else sum(tree.size for tree in self._trees)


def _key(start: FloatArray, goal: FloatArray, resolution_m: float) -> tuple[bytes, bytes, float]:
    return (
        np.asarray(start, dtype=float).tobytes(),
        np.asarray(goal, dtype=float).tobytes(),
        float(resolution_m),
    )


class Sampler:
    """The samples of a search: with ``local_share``, near a node of the tree; else uniform in the box."""

    def __init__(self, lower: FloatArray, upper: FloatArray, settings: RrtSettings) -> None:
        self.lower, self.upper, self.share = lower, upper, settings.local_share
        self.span = upper - lower
        self.spread = settings.local_spread * self.span

    def __call__(self, tree: Tree, rng: np.random.Generator) -> FloatArray:
        """A sample for ``tree``, drawn from ``rng``.

        Uniform draws are ``lower + span * rng.random(d)``: the numbers ``rng.uniform(lower,
        upper)`` draws, to the bit (NumPy computes ``low + (high - low) * u`` from the same
        ``u``), without its broadcasting and checks, a few microseconds a sample.
        """
        if self.share and rng.random() < self.share:
            node: FloatArray = tree.nodes[rng.integers(tree.size)]
            drawn = node + self.spread * rng.standard_normal(node.size)
            return np.minimum(np.maximum(drawn, self.lower), self.upper)  # np.clip, without its overhead
        return self.lower + self.span * rng.random(self.lower.size)


def connect(
    tree: Tree, near: int, target: FloatArray, fraction: float, step_m: float, weights: FloatArray
) -> int | None:
    """Grow ``tree`` from node ``near`` along the valid ``fraction`` of the way to ``target``.

    A node every step; returns the node at ``target`` if reached.
    """
    if fraction == 0.0:
        return None
    origin = tree.nodes[near]
    length = float(np.abs(target - origin) @ weights)
    nodes = max(1, math.ceil(fraction * length / step_m))
    parent = near
    for k in range(1, nodes + 1):
        parent = tree.add(origin + (fraction * k / nodes) * (target - origin), parent)
    return parent if fraction == 1.0 else None
