"""An obstacle's touch_links: the links that may touch it are left out of every query, nothing else."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck

Q = np.array([0.3, 0.4, 0.3, 0.0, 0.0])
HOLDING = ("tool_link", "wrist_link")


@pytest.fixture(scope="module")
def robot() -> ck.Robot:
    return ck.load_cpr()


@pytest.fixture(scope="module")
def around_tool(robot: ck.Robot) -> ck.Obstacle:
    """A box around the tool at ``Q``: the fingers at a part they grasp."""
    return ck.Obstacle.box((0.12, 0.12, 0.12), ck.frame_positions(robot, Q), name="part")


def test_the_touching_links_pairs_are_left_out_and_every_other_distance_is_the_full_worlds(
    robot: ck.Robot, around_tool: ck.Obstacle
) -> None:
    full = ck.CollisionWorld(robot, [around_tool])
    touching = ck.CollisionWorld(robot, [dataclasses.replace(around_tool, touch_links=HOLDING)])
    links = {g.name: g.link for g in robot.geometries}
    kept = [pair for pair in full.pairs if links[pair[0]] not in HOLDING]
    assert touching.pairs == tuple(kept) and len(kept) < len(full.pairs)
    rng = np.random.default_rng(7)
    lower, upper = robot.limits.lower, robot.limits.upper
    batch = np.vstack([Q, lower + rng.random((40, robot.nq)) * (upper - lower)])
    for q in batch:  # the oracle: the full world's distances of the pairs kept
        every = {(p.robot_geometry, p.obstacle): p.distance_m for p in full.clearance(q).pairs}
        mine = {(p.robot_geometry, p.obstacle): p.distance_m for p in touching.clearance(q).pairs}
        assert mine == {(g, o): every[g, o] for g, o, _ in kept}
    oracle = np.array(
        [
            min(p.distance_m for p in full.clearance(q).pairs if p.robot_geometry in {k[0] for k in kept})
            for q in batch
        ]
    )
    found, _ = touching.min_clearance_batch(batch)
    np.testing.assert_allclose(found, oracle, atol=1e-9)
    assert full.margin_violated(Q[None], 0.05)[0] and oracle[0] > 0.05  # only the fingers are at it
    np.testing.assert_array_equal(touching.margin_violated(batch, 0.05), oracle < 0.05)


def test_a_curve_through_the_part_is_certified_for_the_links_that_may_touch_it(
    robot: ck.Robot, around_tool: ck.Obstacle
) -> None:
    q0, q1 = Q + np.array([0.0, 0.0, 0.05, 0.0, 0.0]), Q - np.array([0.0, 0.0, 0.05, 0.0, 0.0])

    def curve(t: np.ndarray) -> np.ndarray:
        return np.asarray(q0 + np.asarray(t)[:, None] * (q1 - q0), dtype=float)

    speed = np.abs(q1 - q0)
    touching = ck.CollisionWorld(robot, [dataclasses.replace(around_tool, touch_links=HOLDING)])
    assert not ck.check_curve(ck.CollisionWorld(robot, [around_tool]), curve, 0.0, 1.0, speed, 0.05).accepted
    check = ck.check_curve(touching, curve, 0.0, 1.0, speed, 0.05)
    assert check.accepted
    dense = touching.clearance_batch(curve(np.linspace(0.0, 1.0, 401))).min_clearance_m
    assert check.certified_min_m <= dense.min() + 1e-9


def test_what_the_robot_carries_is_checked_against_it_whatever_holds_it(
    robot: ck.Robot, around_tool: ck.Obstacle
) -> None:
    carried = ck.carrying(robot, ck.Payload(1.0, shape=ck.Obstacle.sphere(0.01, (0, 0, 0)), name="ball"))
    world = ck.CollisionWorld(carried, [dataclasses.replace(around_tool, touch_links=HOLDING)])
    assert ("ball", "part", "effector") in world.pairs
    assert world.clearance(Q).min_clearance_m < 0.0  # the ball inside the box


def test_a_link_the_robot_does_not_have_is_refused_by_name(robot: ck.Robot, around_tool: ck.Obstacle) -> None:
    with pytest.raises(
        ck.CprKinError, match=r"'part' touch_links \['fingr'\] are not links of the robot.*tool_link"
    ):
        ck.CollisionWorld(robot, [dataclasses.replace(around_tool, touch_links=("tool_link", "fingr"))])
    with pytest.raises(ck.ObstacleError, match="must be a sequence of link names"):
        dataclasses.replace(around_tool, touch_links="tool_link")  # type: ignore[arg-type]


def test_what_the_robot_carries_may_touch_the_obstacles_its_payload_names_and_no_other(
    robot: ck.Robot, around_tool: ck.Obstacle
) -> None:
    table = ck.Obstacle.box((0.5, 0.5, 0.02), (0.0, 0.0, -2.0), name="table")
    ball = ck.Payload(1.0, shape=ck.Obstacle.sphere(0.01, (0, 0, 0)), name="ball", touch_obstacles=("part",))
    world = ck.CollisionWorld(ck.carrying(robot, ball), [around_tool, table])
    assert ("ball", "part", "effector") not in world.pairs and ("ball", "table", "effector") in world.pairs
    assert ("tool", "part", "effector") in world.pairs  # the links that hold it are not excused
    bare = ck.carrying(robot, dataclasses.replace(ball, touch_obstacles=()))
    full = ck.CollisionWorld(bare, [around_tool, table])
    kept = {(p.robot_geometry, p.obstacle): p.distance_m for p in world.clearance(Q).pairs}
    every = {(p.robot_geometry, p.obstacle): p.distance_m for p in full.clearance(Q).pairs}
    assert kept == {pair: d for pair, d in every.items() if pair != ("ball", "part")}  # the oracle
    with pytest.raises(ck.CprKinError, match=r"payload 'ball' touch_obstacles \['tabel'\] are not obstacles"):
        ck.CollisionWorld(ck.carrying(robot, dataclasses.replace(ball, touch_obstacles=("tabel",))), [table])
