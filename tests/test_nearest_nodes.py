"""The k-d tree of a large RRT tree's nodes: the scan's node to the bit, and the true nearest by scipy."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from numpy.typing import NDArray
from scipy.spatial import cKDTree

from planning.search.nearest_nodes import (
    INDEXED_FROM,
    LEAF_NODES,
    REBUILD_SHARE,
    NodeIndex,
    build_cells,
    nearest_node,
)
from planning.search.rrt_trees import Tree

FloatArray = NDArray[np.float64]


def grown_nodes(count: int, joints: int, seed: int) -> FloatArray:
    """Nodes as a tree grows them: each a short step from an earlier one, in the unit box."""
    rng = np.random.default_rng(seed)
    nodes = np.empty((count, joints))
    nodes[0] = 0.5
    for i in range(1, count):
        nodes[i] = np.clip(nodes[rng.integers(i)] + 0.05 * rng.standard_normal(joints), 0.0, 1.0)
    return nodes


@pytest.mark.parametrize(("count", "indexed", "joints", "seed"), [(3000, 2600, 7, 0), (5000, 5000, 8, 1)])
def test_the_index_answers_the_scans_node_and_scipys_distance(
    count: int, indexed: int, joints: int, seed: int
) -> None:
    nodes = grown_nodes(count, joints, seed)
    nodes[[40, 700, count - 1]] = nodes[10]  # duplicates: ties the first must win, one beyond the index
    rng = np.random.default_rng(seed + 100)
    weights = rng.uniform(0.2, 1.5, joints)
    index = NodeIndex(nodes, indexed, weights)
    queries = np.vstack([rng.random((300, joints)), nodes[[10, 5, 2999]], nodes[:50] + 1e-9])
    scipy_tree = cKDTree(nodes * weights)  # the weighted L1 distance as scipy's on scaled nodes
    for q in queries:
        found = index.nearest(nodes, count, q, weights)
        assert found == nearest_node(nodes, count, q, weights)
        distance, _ = scipy_tree.query(q * weights, p=1)
        assert np.abs(nodes[found] - q) @ weights == pytest.approx(distance, rel=1e-12, abs=1e-15)
    assert index.nearest(nodes, count, nodes[10], weights) == 10


def test_the_cells_cover_every_node_once_within_their_boxes() -> None:
    nodes = grown_nodes(2500, 6, 2)
    weights = np.ones(6)
    order, low, high, first_child, start, end = build_cells(nodes, len(nodes), weights, LEAF_NODES)
    assert sorted(order.tolist()) == list(range(len(nodes)))
    leaves = np.flatnonzero(first_child < 0)
    assert sum(int(end[c] - start[c]) for c in leaves) == len(nodes)
    assert all(end[c] - start[c] <= LEAF_NODES for c in leaves)
    for cell in range(len(first_child)):
        members = nodes[order[start[cell] : end[cell]]]
        np.testing.assert_array_equal(members.min(axis=0), low[cell])
        np.testing.assert_array_equal(members.max(axis=0), high[cell])
        child = first_child[cell]
        if child >= 0:  # the two children split the cell's nodes between them
            assert (start[child], end[child + 1]) == (start[cell], end[cell])
            assert end[child] == start[child + 1]


def test_identical_nodes_make_one_leaf_and_a_nan_query_the_scans_answer() -> None:
    nodes = np.tile([[0.3, 0.7]], (INDEXED_FROM, 1))
    order, *_, first_child, _, _ = build_cells(nodes, len(nodes), np.ones(2), LEAF_NODES)
    assert first_child.tolist() == [-1] and len(order) == INDEXED_FROM  # no extent to split along
    index = NodeIndex(nodes, len(nodes), np.ones(2))
    assert index.nearest(nodes, len(nodes), np.array([0.0, 0.0]), np.ones(2)) == 0
    nan = np.array([np.nan, 0.5])
    scanned = nearest_node(nodes, len(nodes), nan, np.ones(2))
    assert index.nearest(nodes, len(nodes), nan, np.ones(2)) == scanned


def test_a_tree_indexes_its_nodes_past_the_threshold_and_again_as_it_grows() -> None:
    rng = np.random.default_rng(3)
    nodes, weights = grown_nodes(3 * INDEXED_FROM, 5, 3), rng.uniform(0.5, 2.0, 5)
    tree = Tree(nodes[0])
    sizes = []
    for node in nodes[1:]:
        tree.add(node, 0)
        q = rng.random(5)
        assert tree.nearest(q, weights) == nearest_node(tree.nodes, tree.size, q, weights)
        index = tree._index
        sizes.append(0 if index is None else index.size)
    built = sorted(set(sizes))
    assert built[0] == 0 and built[1] == INDEXED_FROM  # a scan below the threshold
    for smaller, larger in itertools.pairwise(built[1:]):  # rebuilt once the new ones reach the share
        assert larger == smaller + int(np.ceil(REBUILD_SHARE * smaller))
