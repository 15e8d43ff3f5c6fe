"""Pairs screened in blocks: every pair in one block, clusters enclosing their capsules, the same answer."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.bounds.pair_bounds import JointCapsules, joint_capsules
from cpr_kin.bounds.self_blocks import CLUSTER_RADIUS_M, PairBlocks
from cpr_kin.bounds.self_bounds import SelfPairBounds
from cpr_kin.model.packages import example_robot_data_share

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"

# Baxter's left arm (355 pairs: its gripper's links against a body fixed to the world) and
# Panda's arm (21 pairs), each with its SRDF's disabled pairs
ARMS = {
    "baxter": (
        "baxter_description/urdf/baxter.urdf",
        "left_gripper",
        "baxter_description/srdf/baxter_manipulation.srdf",
    ),
    "panda": ("panda_description/urdf/panda.urdf", None, None),
}


@pytest.fixture(scope="module", params=sorted(ARMS))
def arm(request: pytest.FixtureRequest) -> ck.Robot:
    urdf, tcp, srdf = ARMS[request.param]
    return ck.load_robot(ROBOTS / urdf, tcp=tcp, srdf=None if srdf is None else ROBOTS / srdf)


def capsules_and_pairs(arm: ck.Robot) -> tuple[JointCapsules, list[tuple[int, int]]]:
    pairs = list(ck.CollisionWorld(arm, []).self_collision._pairs)
    geometries = sorted({g for pair in pairs for g in pair})
    slot = {g: k for k, g in enumerate(geometries)}
    return joint_capsules(arm.collision_model, geometries), [(slot[a], slot[b]) for a, b in pairs]


def test_every_pair_is_in_one_block(arm: ck.Robot) -> None:
    capsules, pairs = capsules_and_pairs(arm)
    blocks = PairBlocks.build(capsules, pairs)
    assert sorted(zip(blocks.pair_a.tolist(), blocks.pair_b.tolist(), strict=True)) == sorted(pairs)
    assert blocks.start[0] == 0 and blocks.start[-1] == len(pairs) and np.all(np.diff(blocks.start) > 0)
    for k in range(len(blocks.block_a)):  # a block's pairs join its two clusters' capsules
        members = slice(blocks.start[k], blocks.start[k + 1])
        assert {blocks.joint[blocks.block_a[k]]} == set(capsules.joint[blocks.pair_a[members]])
        assert {blocks.joint[blocks.block_b[k]]} == set(capsules.joint[blocks.pair_b[members]])
    if len(pairs) > 100:  # a robot with many links has blocks of many pairs
        assert len(blocks.block_a) < len(pairs) / 5


def test_each_cluster_encloses_its_capsules(arm: ck.Robot) -> None:
    capsules, pairs = capsules_and_pairs(arm)
    blocks = PairBlocks.build(capsules, pairs)
    sizes = np.diff(blocks.start)
    cluster_of = dict(zip(blocks.pair_a.tolist(), np.repeat(blocks.block_a, sizes).tolist(), strict=True))
    cluster_of.update(zip(blocks.pair_b.tolist(), np.repeat(blocks.block_b, sizes).tolist(), strict=True))
    for slot, cluster in cluster_of.items():
        assert capsules.joint[slot] == blocks.joint[cluster]
        # the capsule's ends and radius within the cluster's sphere, in the joint's frame
        reach = np.linalg.norm(capsules.ends[slot] - blocks.centre[cluster], axis=1) + capsules.radius[slot]
        assert reach.max() <= blocks.radius[cluster] + 1e-12
    for cluster in set(cluster_of.values()):
        if list(cluster_of.values()).count(cluster) > 1:
            assert blocks.radius[cluster] <= CLUSTER_RADIUS_M


@pytest.mark.parametrize("threshold_m", [-0.01, 0.0, 0.02, 0.1])
def test_the_blocks_answer_as_the_pairs_do(arm: ck.Robot, threshold_m: float) -> None:
    collision = ck.CollisionWorld(arm, []).self_collision
    bounds = SelfPairBounds(arm.model, collision.geometry_model, collision._pairs)
    q = np.random.default_rng(4).uniform(arm.limits.lower, arm.limits.upper, (3000, arm.nq))
    pair_by_pair = np.asarray((bounds(q, threshold_m) <= threshold_m).any(axis=1))
    assert 0.05 < pair_by_pair.mean() < 0.95  # both answers occur
    np.testing.assert_array_equal(bounds.any_below(q, threshold_m), pair_by_pair)
    one_by_one = [bool(bounds.any_below(x[None], threshold_m)[0]) for x in q[:50]]
    np.testing.assert_array_equal(one_by_one, pair_by_pair[:50])
