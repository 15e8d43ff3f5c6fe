"""Near self pairs remembered on a grid over their joints: never clearer than coal, and learned once."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.pair_cells import CLEAR, cell_states
from cpr_kin.collision.learned_cells import LearnedCells
from cpr_kin.collision.near_cells import LEVEL_M, TESTED_ABOVE_M, NearCells
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.shapes.exact_pairs import ExactPairs
from planning.bench.mbm import vamp_resources


@pytest.fixture(scope="module")
def panda() -> ck.Robot:
    """MotionBenchMaker's Panda (vamp-planner's, from PyPI, cached): its hand's pairs are near."""
    return ck.load_robot(vamp_resources("panda") / "panda.urdf", srdf=vamp_resources("panda") / "panda.srdf")


def geometry(robot: ck.Robot, link: str) -> int:
    return next(k for k, g in enumerate(robot.geometries) if g.link == link)


def near_cells(robot: ck.Robot, pairs: list[tuple[int, int]]) -> NearCells:
    return NearCells(robot.model, robot.collision_model, pairs, robot_reach(robot))


def hull_distances(cells: NearCells, q: np.ndarray) -> np.ndarray:
    """``(N, K)`` coal's distance of each near pair on the hulls."""
    model, geometry_model = cells.model, cells.geometry_model
    data, geometry_data = model.createData(), geometry_model.createData()
    found = np.empty((len(q), len(geometry_model.collisionPairs)))
    for n, x in enumerate(q):
        pin.computeDistances(model, data, geometry_model, geometry_data, x)
        found[n] = [r.min_distance for r in geometry_data.distanceResults]
    return found


def hand_pairs(panda: ck.Robot) -> list[tuple[int, int]]:
    """The Panda's near pairs: its fifth link against its seventh and against its hand."""
    link5 = geometry(panda, "panda_link5")
    return [(link5, geometry(panda, "panda_link7")), (link5, geometry(panda, "panda_hand"))]


@pytest.mark.parametrize("margin_m", [0.0, 0.001, 0.006])
def test_a_cleared_configuration_is_farther_than_its_margin_and_the_far_ones_are_cleared(
    panda: ck.Robot, margin_m: float
) -> None:
    cells = near_cells(panda, hand_pairs(panda))
    assert cells
    rng = np.random.default_rng(1)
    q = rng.uniform(panda.limits.lower, panda.limits.upper, (3000, panda.nq))
    distance = hull_distances(cells, q)
    margins = [margin_m] * 2
    clear = cells.clear(q, margins)
    assert np.all(distance[clear] >= margin_m) and not clear.all()
    grids = cells.grids
    assert grids is not None
    found = np.empty((len(q), 2), dtype=np.int64)  # every cell, none known
    unknown = LearnedCells(grids.size).arrays()  # nothing cleared, nothing refused, no centre measured
    cell_states(q, *grids.arrays(), *unknown, np.zeros(2, np.float32), found, np.empty(len(q), np.int8))
    # a configuration whose cells' centres clear the first test is cleared
    at_centres = [hull_distances(cells, grids.centres(k, found[:, k], q))[:, k] for k in range(2)]
    level = np.ceil((margins[0] + 1e-6) / LEVEL_M) * LEVEL_M
    sure = np.all(np.transpose(at_centres) >= level + TESTED_ABOVE_M + grids.slack_m + 1e-5, axis=1)
    assert sure.sum() > 1000 and np.all(clear[sure])
    assert clear.sum() > sure.sum()  # and some of those whose centres are nearer, at the margin asked


def test_a_cell_is_tested_once_and_a_larger_margin_tests_it_again(panda: ck.Robot) -> None:
    cells = near_cells(panda, hand_pairs(panda))
    q = np.random.default_rng(2).uniform(panda.limits.lower, panda.limits.upper, (500, panda.nq))
    first = cells.clear(q, [0.001, 0.001])
    tested = cells.tested
    assert tested > 0
    np.testing.assert_array_equal(cells.clear(q, [0.001, 0.001]), first)
    np.testing.assert_array_equal(cells.clear(q[::-1], [0.0012, 0.0011]), first[::-1])  # the same level
    assert cells.tested == tested  # answered from memory
    cells.clear(q, [0.001 + 2 * TESTED_ABOVE_M, 0.001])
    assert cells.tested > tested


def test_near_a_refused_cells_centre_a_configuration_clears_by_the_distance_measured_there(
    panda: ck.Robot,
) -> None:
    cells = near_cells(panda, hand_pairs(panda))
    grids = cells.grids
    assert grids is not None
    q = np.random.default_rng(6).uniform(panda.limits.lower, panda.limits.upper, (3000, panda.nq))
    margins = [0.02, 0.02]  # most of the hand's cells do not clear 2 cm as a whole
    clear = cells.clear(q, margins)
    learned = cells.memory.kinds[False]
    assert np.isfinite(learned.centre_m).sum() > 100  # measured where a cell was refused
    cells_alone = LearnedCells(grids.size)
    cells_alone.cleared[:], cells_alone.refused[:] = learned.cleared, learned.refused
    _, states = cells._states(grids, q, cells._level(tuple(margins)), cells_alone)
    by_centre = clear & (states != CLEAR)
    assert by_centre.sum() > 20
    # never clearer than coal (the oracle): each pair is at least its margin apart
    assert np.all(hull_distances(cells, q)[clear] >= 0.02)


def test_a_pair_without_a_grid_is_left_out_and_the_others_keep_theirs(panda: ck.Robot) -> None:
    hand = hand_pairs(panda)
    apart = (geometry(panda, "panda_link3"), geometry(panda, "panda_link7"))  # four joints between
    cells = near_cells(panda, [hand[0], apart, hand[1]])
    assert cells.pairs == tuple(hand) and len(cells.geometry_model.collisionPairs) == 2
    q = np.random.default_rng(3).uniform(panda.limits.lower, panda.limits.upper, (500, panda.nq))
    margins = [0.001, 0.001]
    np.testing.assert_array_equal(cells.clear(q, margins), near_cells(panda, hand).clear(q, margins))
    alone = near_cells(panda, [apart])
    assert not alone and alone.pairs == () and alone.grids is None
    assert not alone.clear(q[:20], []).any() and alone.tested == 0


def test_the_robots_screen_keeps_its_cells_across_worlds(panda: ck.Robot) -> None:
    world = ck.CollisionWorld(panda, [], self_margin_m=0.001)
    screen = world.self_collision._screen
    assert screen is not None and screen.near_cells
    q = np.random.default_rng(4).uniform(panda.limits.lower, panda.limits.upper, (200, panda.nq))
    distance, _ = world.self_collision.distances(q)
    for margin_m in (0.0, 0.001):
        np.testing.assert_array_equal(world.self_collision.violated(q, margin_m), distance < margin_m)
    tested = screen.near_cells.tested
    again = ck.CollisionWorld(panda, [], self_margin_m=0.001)
    assert again.self_collision._screen is screen
    again.self_collision.violated(q, 0.001)
    assert screen.near_cells.tested == tested


def mesh_distances(cells: NearCells, exact: ExactPairs, q: np.ndarray) -> np.ndarray:
    """``(N, K)`` each near pair's distance on its exact meshes (the hulls' where it has none)."""
    model, geometry_model = cells.model, cells.geometry_model
    data, geometry_data = model.createData(), geometry_model.createData()
    found = np.empty((len(q), len(geometry_model.collisionPairs)))
    for n, x in enumerate(q):
        pin.computeDistances(model, data, geometry_model, geometry_data, x)
        hulls = [r.min_distance for r in geometry_data.distanceResults]
        found[n] = [exact.distance(geometry_data, k, hull) for k, hull in enumerate(hulls)]
    return found


def test_on_the_meshes_a_concave_links_cells_clear_what_its_hull_does_not() -> None:
    ur5 = ck.load_robot(vamp_resources("ur5") / "ur5.urdf", srdf=vamp_resources("ur5") / "ur5.srdf")
    world = ck.CollisionWorld(ur5, [], self_margin_m=0.001)
    screen = world.self_collision._screen
    assert screen is not None and screen.near_cells and ur5.exact_meshes
    pairs = [p for p, near in zip(world.self_collision._pairs, screen.near, strict=True) if near]
    cells = NearCells(ur5.model, ur5.collision_model, pairs, robot_reach(ur5), ur5.exact_meshes)
    hulls_only = near_cells(ur5, pairs)
    exact = ExactPairs(cells.geometry_model, ur5.exact_meshes)
    assert exact.refined.all()  # both near pairs have a concave link's mesh
    q = np.random.default_rng(5).uniform(ur5.limits.lower, ur5.limits.upper, (2000, ur5.nq))
    margins = [0.001] * len(pairs)
    on_meshes = cells.clear(q, margins, on_meshes=True)
    on_hulls = cells.clear(q, margins)
    # never clearer than the meshes (the oracle: coal's distance on them), nor the hulls than the hulls
    assert np.all(mesh_distances(cells, exact, q)[on_meshes] >= 0.001)
    assert np.all(hull_distances(cells, q)[on_hulls] >= 0.001)
    # the meshes clear more, and what they learned is not the hulls'
    assert on_meshes.sum() > on_hulls.sum() + 100 and np.all(on_meshes[on_hulls])
    np.testing.assert_array_equal(on_hulls, hulls_only.clear(q, margins))
    # without meshes, a test on the meshes is the hulls' test
    np.testing.assert_array_equal(hulls_only.clear(q, margins, on_meshes=True), on_hulls)
