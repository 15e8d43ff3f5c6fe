"""A grid over the joints between a pair's geometries: its cells hold the pair's distance within a slack."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.pair_cells import DOUBTFUL, UNKNOWN, CellGrids, cell_grids, cell_states
from cpr_kin.bounds.reach import relative_radii
from cpr_kin.collision.learned_cells import LearnedCells
from cpr_kin.collision.robot_reach import robot_reach
from planning.bench.mbm import vamp_resources


@pytest.fixture(scope="module")
def panda() -> ck.Robot:
    """MotionBenchMaker's Panda (vamp-planner's, from PyPI, cached)."""
    return ck.load_robot(vamp_resources("panda") / "panda.urdf", srdf=vamp_resources("panda") / "panda.srdf")


def geometry(robot: ck.Robot, link: str) -> int:
    return next(k for k, g in enumerate(robot.geometries) if g.link == link)


def hand_pairs(panda: ck.Robot) -> list[tuple[int, int]]:
    """Its fifth link against its seventh and against its hand: two joints between each."""
    link5 = geometry(panda, "panda_link5")
    return [(link5, geometry(panda, "panda_link7")), (link5, geometry(panda, "panda_hand"))]


def grid_cells(grids: CellGrids | None, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each configuration's cells and state with nothing known (every cell UNKNOWN or beyond)."""
    assert grids is not None
    k = len(grids.offsets)
    found, states = np.empty((len(q), k), dtype=np.int64), np.empty(len(q), dtype=np.int8)
    unknown = LearnedCells(grids.size).arrays()  # nothing cleared, nothing refused, no centre measured
    cell_states(q, *grids.arrays(), *unknown, np.zeros(k, np.float32), found, states)
    return found, states


def pair_distances(robot: ck.Robot, pairs: list[tuple[int, int]], q: np.ndarray) -> np.ndarray:
    """``(N, K)`` coal's distance of each pair (on the hulls)."""
    model, geometry_model = robot.model, robot.collision_model.copy()
    for a, b in pairs:
        geometry_model.addCollisionPair(pin.CollisionPair(a, b))
    data, geometry_data = model.createData(), geometry_model.createData()
    found = np.empty((len(q), len(pairs)))
    for n, x in enumerate(q):
        pin.computeDistances(model, data, geometry_model, geometry_data, x)
        found[n] = [r.min_distance for r in geometry_data.distanceResults]
    return found


@pytest.mark.parametrize("slack_m", [0.004, 0.01])
def test_a_pairs_distance_anywhere_in_a_cell_is_within_its_slack_of_the_centres(
    panda: ck.Robot, slack_m: float
) -> None:
    pairs = hand_pairs(panda)
    radii = relative_radii(panda.model, panda.collision_model, pairs, robot_reach(panda))
    grids = cell_grids(panda.model, radii, np.full(2, slack_m))
    assert grids is not None and grids.joints.tolist() == [[5, 6], [5, 6]]  # joints 6 and 7
    q = np.random.default_rng(0).uniform(panda.limits.lower, panda.limits.upper, (400, panda.nq))
    found, states = grid_cells(grids, q)
    assert np.all(states == UNKNOWN)
    at_q = pair_distances(panda, pairs, q)
    for k in range(2):
        centres = grids.centres(k, found[:, k], q)
        joints = grids.joints[k]
        np.testing.assert_array_equal(np.delete(centres, joints, axis=1), np.delete(q, joints, axis=1))
        offset = centres[:, joints] - q[:, joints]
        offset = (offset + np.pi) % (2 * np.pi) - np.pi  # revolute joints: a turn apart is the same
        assert np.all(np.abs(offset) <= grids.step[k] / 2 + 1e-9)
        assert np.all(radii[k, joints] * grids.step[k] / 2 <= slack_m / 2 + 1e-12)
        gap = np.abs(pair_distances(panda, pairs, centres)[:, k] - at_q[:, k])
        assert gap.max() <= slack_m + 1e-9
        assert gap.max() > 0.05 * slack_m  # the cells are not needlessly small either


def test_a_pair_with_more_joints_between_or_too_many_cells_has_no_grid(panda: ck.Robot) -> None:
    pairs = [(geometry(panda, "panda_link3"), geometry(panda, "panda_link7"))]  # four joints between
    radii = relative_radii(panda.model, panda.collision_model, pairs, robot_reach(panda))
    assert np.count_nonzero(radii) == 4 and cell_grids(panda.model, radii, np.array([0.01])) is None
    fine = relative_radii(panda.model, panda.collision_model, hand_pairs(panda)[:1], robot_reach(panda))
    assert cell_grids(panda.model, fine, np.array([1e-5])) is None  # millions of cells


def test_a_joint_is_tiled_within_its_limits_and_a_revolute_one_of_a_turn_or_more_wraps(
    robot: ck.Robot,
) -> None:
    # the CPR's second and third joints slide; its first and fourth turn, less than a turn
    model = robot.model.copy()
    model.lowerPositionLimit[3], model.upperPositionLimit[3] = -4.0, 4.0  # the fourth: more than a turn
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    radii = np.zeros((3, robot.nq))
    radii[0, [1, 2]] = 1.0
    radii[1, 0] = 0.5
    radii[2, 3] = 0.5
    grids = cell_grids(model, radii, np.full(3, 0.01))
    assert grids is not None
    np.testing.assert_allclose(grids.origin[0], lower[[1, 2]])
    np.testing.assert_allclose(grids.step[0] * grids.counts[0], upper[[1, 2]] - lower[[1, 2]])
    assert np.all(grids.step[0] <= 0.01) and grids.turn[0].tolist() == [0.0, 0.0]
    assert grids.origin[1, 0] == lower[0] and grids.step[1, 0] * grids.counts[1, 0] == pytest.approx(5.8)
    assert grids.turn[1, 0] == 0.0 and grids.step[1, 0] * 0.5 / 2 <= 0.01
    assert grids.turn[2, 0] == pytest.approx(2 * np.pi) and grids.step[2, 0] * grids.counts[
        2, 0
    ] == pytest.approx(2 * np.pi)
    assert grids.joints[1].tolist() == [0, -1] and grids.offsets[1] == np.prod(grids.counts[0])
    q = np.tile((lower + upper) / 2, (5, 1))
    q[1, 1] = upper[1] + 0.001  # beyond the travel: no cell
    q[2, 3] += 2 * np.pi  # a turn later: the same cell
    q[3, 1] = lower[1]  # at the travel's end: its first cell
    q[4, 0] = upper[0] + 0.001  # beyond the first joint's limit, although the geometry would be the same
    found, states = grid_cells(grids, q)
    assert states.tolist() == [UNKNOWN, DOUBTFUL, UNKNOWN, UNKNOWN, DOUBTFUL]
    assert found[2, 2] == found[0, 2] and found[0, 0] != found[3, 0]
    assert found[3, 0] - grids.offsets[0] < grids.strides[0, 0]
