"""The compiled peer (roboplan): our collision model given to it, its plans, our checks of its paths."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from planning.bench.roboplan_rrt import RoboplanPeer
from planning.io.scene_file import parse_scene

pytest.importorskip("roboplan.core", reason="the bench extra's roboplan")

READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
SCENE = {
    "robot": "panda",
    "start": {"q": READY},
    "goal": {"q": [1.2, 0.2, 0.0, -1.8, 0.0, 2.0, 0.785]},
    "safety_margin": 0.0,
    "self_margin": 0.0,
    "obstacles": [
        {"name": "post", "shape": "box", "size": [0.1, 0.1, 0.8], "xyz": [0.45, 0.35, 0.4]},
        {"name": "ball", "shape": "sphere", "radius": 0.08, "xyz": [0.3, -0.4, 0.6]},
        {"name": "pipe", "shape": "cylinder", "radius": 0.03, "length": 0.6, "xyz": [-0.4, 0.3, 0.5]},
        {  # a scanned board: voxels, an octree in roboplan
            "name": "board",
            "shape": "point_cloud",
            "points": np.random.default_rng(3).uniform([-0.2, -0.2, 0], [0.2, 0.2, 0.02], (300, 3)).tolist(),
            "resolution": 0.04,
            "xyz": [-0.2, -0.45, 0.45],
        },
    ],
}


@pytest.fixture(scope="module")
def peer() -> RoboplanPeer:
    return RoboplanPeer(parse_scene(SCENE))


def test_the_peer_sees_our_collision_model(peer: RoboplanPeer) -> None:
    """Where our model is clear or in contact by more than a millimetre, roboplan says the same."""
    world, robot = peer.problem.world, peer.problem.robot
    rng = np.random.default_rng(2)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, (400, robot.nq))
    obstacles = world.clearance_batch(q).min_clearance_m
    own, _ = world.self_collision.distances(q)
    ours = np.minimum(obstacles, own)
    full = np.array(peer.scene.getCurrentJointPositions())
    index = peer.scene.getJointPositionIndices(list(robot.joint_names))
    theirs = []
    for row in q:
        full[index] = row
        theirs.append(peer.scene.hasCollisions(full))
    theirs_collide = np.array(theirs)
    clear, touching = ours > 1e-3, ours < -1e-3
    assert clear.sum() > 50 and touching.sum() > 50  # both kinds drawn
    assert not theirs_collide[clear].any() and theirs_collide[touching].all()


def test_a_plan_ends_at_the_problem_s_ends_and_our_verdict_is_the_dense_one(peer: RoboplanPeer) -> None:
    verdicts = []
    for seed in range(4):
        result = peer.plan(5.0, seed)
        assert result.success and result.planning_time_s > 0 and result.duration_s > 0
        np.testing.assert_allclose(result.waypoints[0], peer.problem.q_start, atol=1e-9)
        np.testing.assert_allclose(result.waypoints[-1], peer.problem.q_goal, atol=1e-9)
        times, positions, *_ = result.samples
        assert times[-1] == pytest.approx(result.duration_s)
        np.testing.assert_allclose(positions[-1], peer.problem.q_goal, atol=1e-6)
        s = np.linspace(0.0, 1.0, 2001)[:, None]
        dense = np.vstack([a + s * (b - a) for a, b in itertools.pairwise(result.waypoints)])
        world = peer.problem.world
        lowest = min(
            world.clearance_batch(dense).min_clearance_m.min(), world.self_collision.distances(dense)[0].min()
        )
        if result.certified_fine:  # certified: no dense sample may be in contact
            assert lowest >= 0.0
        verdicts.append((result.certified, result.certified_fine))
    assert all(fine or not certified for certified, fine in verdicts)  # the finer step never refuses more


def test_a_path_through_an_obstacle_is_refused_at_every_step(peer: RoboplanPeer) -> None:
    through = np.array([READY, [0.7, 0.4, 0.0, -1.8, 0.0, 2.0, 0.785], READY])
    world = peer.problem.world
    s = np.linspace(0.0, 1.0, 201)[:, None]
    dense = np.vstack([a + s * (b - a) for a, b in itertools.pairwise(through)])
    assert world.clearance_batch(dense).min_clearance_m.min() < 0  # the post is in the way
    assert not peer.certified(through) and not peer.certified(through, step_share=0.1)
