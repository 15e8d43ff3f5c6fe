from __future__ import annotations

import dataclasses
import re

import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.certified.motion import PATH_WEIGHT_FLOOR
from cpr_kin.model.packages import example_robot

from .conftest import PAPER_GOAL_TCP, PAPER_START_TCP, after_calls, random_configurations


@pytest.fixture(scope="module")
def surface_points(robot: ck.Robot) -> list[np.ndarray]:
    """Points on each collision geometry's surface, in its own frame."""
    points = []
    for g in robot.geometries:
        shape = robot.collision_model.geometryObjects[g.index].geometry
        if type(shape).__name__ == "Box":
            mesh = trimesh.creation.box(extents=2 * np.asarray(shape.halfSide))
        else:
            mesh = trimesh.creation.cylinder(radius=shape.radius, height=2 * shape.halfLength, sections=64)
        points.append(np.asarray(mesh.vertices))
    return points


def world_points(robot: ck.Robot, q: np.ndarray, surface_points: list[np.ndarray]) -> np.ndarray:
    data = robot.model.createData()
    gdata = robot.collision_model.createData()
    pin.updateGeometryPlacements(robot.model, data, robot.collision_model, gdata, q)
    placements = [gdata.oMg[g.index] for g in robot.geometries]
    return np.vstack(
        [p @ m.rotation.T + m.translation for m, p in zip(placements, surface_points, strict=True)]
    )


def test_radii_values(robot: ck.Robot) -> None:
    radii = ck.motion_radii(robot)
    np.testing.assert_array_equal(radii[1:3], [1.0, 1.0])
    # theta1 carries the tool, pitched horizontal at full reach: 0.8 + 0.15 (+ corner)
    assert 0.95 < radii[0] < 0.97
    # the wrist joints carry the 0.15 m tool
    assert 0.15 < radii[3] < 0.16 and 0.15 < radii[4] < 0.16


def test_path_weights_are_the_radii_with_no_zero(robot: ck.Robot) -> None:
    np.testing.assert_array_equal(ck.path_weights(robot), ck.motion_radii(robot))  # none zero: the same
    so100 = ck.load_robot(example_robot("so100"))  # its wrist roll and gripper carry no collision mesh
    radii, weights = ck.motion_radii(so100), ck.path_weights(so100)
    moving_nothing = radii == 0.0
    assert moving_nothing.tolist() == [False, False, False, False, True, True]
    np.testing.assert_array_equal(weights[~moving_nothing], radii[~moving_nothing])
    np.testing.assert_allclose(weights[moving_nothing], PATH_WEIGHT_FLOOR * radii.max())


def test_reach_is_computed_once_per_robot(robot: ck.Robot) -> None:
    from cpr_kin.bounds.reach import geometry_reach
    from cpr_kin.collision.robot_reach import robot_reach

    cached = robot_reach(robot)
    assert robot_reach(robot) is cached
    fresh = geometry_reach(robot.model, robot.collision_model, robot.limits.lower, robot.limits.upper)
    for a, b in zip(cached, fresh, strict=True):
        np.testing.assert_array_equal(a.radii, b.radii)
    other = ck.load_cpr()  # another robot gets its own
    assert robot_reach(other) is not cached
    np.testing.assert_array_equal(ck.motion_radii(other), ck.motion_radii(robot))


def test_radii_bound_every_point_motion(
    robot: ck.Robot, rng: np.random.Generator, surface_points: list[np.ndarray]
) -> None:
    radii = ck.motion_radii(robot)
    worst_ratio = 0.0
    for q in random_configurations(robot, rng, 300):
        dq = rng.normal(size=robot.nq) * rng.uniform(1e-4, 0.05)
        q2 = np.clip(q + dq, robot.limits.lower, robot.limits.upper)
        moved = np.linalg.norm(
            world_points(robot, q2, surface_points) - world_points(robot, q, surface_points), axis=1
        ).max()
        bound = radii @ np.abs(q2 - q)
        assert moved <= bound + 1e-12
        worst_ratio = max(worst_ratio, moved / bound)
    # single-joint motions show the bound is tight, not merely valid
    q = np.array([0.0, 0.3, 0.5, 0.0, -1.6])  # tool pitched outward, horizontal
    step = np.array([1e-3, 0, 0, 0, 0])
    moved = np.linalg.norm(
        world_points(robot, q + step, surface_points) - world_points(robot, q, surface_points), axis=1
    ).max()
    assert moved / (radii @ step) > 0.99


def test_paper_swing_rejected(robot: ck.Robot, paper_world: ck.CollisionWorld) -> None:
    start, goal = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    check = ck.check_segment(paper_world, start, goal, margin_m=0.1)
    assert not check.accepted
    assert check.worst_pair == ("tool", "crate")
    assert check.worst_group == "effector"
    assert set(check.violating_groups) == {"effector", "links"}
    assert check.certified_min_m <= check.sampled_min_m


def test_lifted_swing_accepted(robot: ck.Robot, paper_world: ck.CollisionWorld) -> None:
    # the same swing with the carriage at the top clears the crate by far
    start = ck.tcp_ik(robot, (0.5, 0.45, 0.65))
    goal = ck.tcp_ik(robot, (-0.5, 0.45, 0.65))
    check = ck.check_segment(paper_world, start, goal, margin_m=0.1)
    assert check.accepted
    assert check.violating_groups == ()
    assert 0.1 < check.certified_min_m <= check.sampled_min_m


@pytest.mark.parametrize("step_m", [0.002, 0.01, 0.05])
def test_samples_respect_the_motion_bound(
    robot: ck.Robot, paper_world: ck.CollisionWorld, step_m: float
) -> None:
    start, goal = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    check = ck.check_segment(paper_world, start, goal, margin_m=0.1, step_m=step_m)
    ds = np.diff(check.times)
    motion_between_checks = ck.motion_radii(robot) @ np.abs(goal - start) * ds
    assert motion_between_checks.max() <= 2 * step_m * (1 + 1e-12)
    assert check.sampled_min_m - check.certified_min_m <= step_m + 1e-12


def test_certified_bound_is_sound(robot: ck.Robot, rng: np.random.Generator) -> None:
    # certified minimum never exceeds what a 50x denser sampling finds
    world = ck.CollisionWorld(robot, [ck.Obstacle.sphere(0.1, (0.2, 0.6, 0.4), name="ball")])
    for _ in range(10):
        a, b = random_configurations(robot, rng, 2)
        check = ck.check_segment(world, a, b, margin_m=0.1, step_m=0.02)
        dense = world.clearance_batch(np.linspace(a, b, 50 * len(check.times))).min_clearance_m.min()
        assert check.certified_min_m <= dense + 1e-9


@pytest.fixture(scope="module")
def cluttered_world(robot: ck.Robot) -> ck.CollisionWorld:
    return ck.CollisionWorld(
        robot,
        [
            ck.Obstacle.box((0.3, 0.3, 0.3), (0.0, 0.6, 0.15), name="crate"),
            ck.Obstacle.sphere(0.1, (0.2, 0.6, 0.4), name="ball"),
            ck.Obstacle.cylinder(0.05, 0.8, (-0.5, 0.3, 0.4), name="post"),
            ck.Obstacle.capsule(0.04, 0.6, (0.4, -0.4, 0.5), (1.2, 0.0, 0.3), name="bar"),
        ],
    )


def test_clearance_lower_bounds_are_below_coal(
    robot: ck.Robot, cluttered_world: ck.CollisionWorld, rng: np.random.Generator
) -> None:
    q = random_configurations(robot, rng, 400)
    bounds = cluttered_world.clearance_lower_bounds(q)
    exact = cluttered_world.clearance_batch(q).clearance_m
    assert np.all(bounds <= exact)
    assert np.isneginf(bounds).any() and np.isfinite(bounds).mean() > 0.5  # informative mostly
    alone = ck.CollisionWorld(robot, [])
    assert np.all(alone.clearance_lower_bounds(q) == np.inf)
    # the pairs' bounds computed once and handed on give the same answers as computed anew
    per_pair = cluttered_world.pair_bounds(q)
    assert per_pair.shape == (len(q), len(cluttered_world.pairs))
    assert alone.pair_bounds(q).shape == (len(q), 0)
    np.testing.assert_array_equal(cluttered_world.clearance_lower_bounds(q, per_pair), bounds)
    for group in range(len(ck.GROUPS)):
        distance, pair = cluttered_world.group_clearance(q[:50], group, per_pair_m=per_pair[:50])
        anew, pair_anew = cluttered_world.group_clearance(q[:50], group)
        np.testing.assert_array_equal(pair, pair_anew)
        np.testing.assert_allclose(distance, anew, atol=2e-6)  # coal's GJK starts warm from the query before


@pytest.mark.parametrize("samples", [60, 300, 1500])
def test_decisive_clearance_finds_the_minima_of_the_full_evaluation(
    robot: ck.Robot, cluttered_world: ck.CollisionWorld, rng: np.random.Generator, samples: int
) -> None:
    from cpr_kin.certified.motion import decisive_clearance

    saved = 0
    for _ in range(8):  # random joint-space segments, sampled densely
        a, b = random_configurations(robot, rng, 2)
        q = np.linspace(a, b, samples)
        slack_m = np.abs(np.diff(q, axis=0)) @ ck.motion_radii(robot)  # the motion between samples
        full = cluttered_world.clearance_batch(q)
        lazy = decisive_clearance(cluttered_world, q, slack_m)
        exact = lazy.closest_pair >= 0
        saved += int((~exact).sum())
        # coal's distances depend slightly on the order of the queries (GJK's warm start):
        # about 1e-6 of 0.27 m between two runs of the same configuration
        tolerance = 2e-6
        np.testing.assert_allclose(lazy.clearance_m[exact], full.clearance_m[exact], atol=tolerance)
        assert np.all(lazy.clearance_m <= full.clearance_m + tolerance)  # bounds and exact values
        certified = [0.5 * (c[:-1] + c[1:] - slack_m[:, None]) for c in (lazy.clearance_m, full.clearance_m)]
        np.testing.assert_allclose(certified[0].min(axis=0), certified[1].min(axis=0), atol=tolerance)
        worst = np.unravel_index(np.argmin(lazy.clearance_m), lazy.clearance_m.shape)
        assert exact[worst]
        assert lazy.clearance_m[worst] == pytest.approx(full.clearance_m.min(), abs=tolerance)
    assert saved > 0.3 * 8 * samples * 2  # and coal was spared most samples


def test_thin_plate_between_samples_is_caught(robot: ck.Robot) -> None:
    # a 2 mm plate crossed by the tool; with coarse checks every sample may miss it, but the
    # certified bound cannot
    plate = ck.Obstacle.box((0.002, 0.6, 0.6), (0.0, 0.6, 0.3), name="plate")
    world = ck.CollisionWorld(robot, [plate])
    start, goal = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    check = ck.check_segment(world, start, goal, margin_m=0.0, step_m=0.1)
    assert not check.accepted
    assert check.certified_min_m < 0.0


def test_curve_interface_and_errors(robot: ck.Robot, paper_world: ck.CollisionWorld) -> None:
    q0 = ck.tcp_ik(robot, (0.5, 0.45, 0.65))

    def hold(t: np.ndarray) -> np.ndarray:
        return np.tile(q0, (len(t), 1))

    still = ck.check_curve(paper_world, hold, 0.0, 2.0, np.zeros(5), margin_m=0.1)
    assert still.accepted and len(still.times) == 2
    with pytest.raises(ck.CprKinError, match="speed bound"):
        ck.check_curve(paper_world, hold, 0.0, 1.0, -np.ones(5), margin_m=0.1)
    with pytest.raises(ck.CprKinError, match=re.escape("motion step 0.0 m")):
        ck.check_curve(paper_world, hold, 0.0, 1.0, np.ones(5), margin_m=0.1, step_m=0.0)
    with pytest.raises(ck.CprKinError, match=r"time interval \[1.0, 0.0\]"):
        ck.check_curve(paper_world, hold, 1.0, 0.0, np.ones(5), margin_m=0.1)


def test_a_check_that_would_take_minutes_is_refused(paper_world: ck.CollisionWorld) -> None:
    def still(t: np.ndarray) -> np.ndarray:
        return np.tile(ck.tcp_ik(paper_world.robot, (0.5, 0.45, 0.25)), (len(t), 1))

    speeds = paper_world.robot.limits.velocity  # a bound, however still the curve
    with pytest.raises(ck.CprKinError, match=r"the continuous check needs \d+ samples .* at most 1000000"):
        ck.check_curve(paper_world, still, 0.0, 600.0, speeds, 0.1, step_m=1e-4)


def test_each_interval_bounded_by_its_own_speed_certifies_an_approach_to_rest_near_an_obstacle(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    """A rest-to-rest motion (``s = 3 t^2 - 2 t^3``) ending 2 mm from a ball: one speed bound for
    the whole motion leaves a step's worth of motion between the last samples and cannot certify
    it with margin 0; each interval's own bound (from the speeds at its ends and the peak
    acceleration) can, and stays below what a 50x denser sampling finds."""
    start, goal = ck.tcp_ik(robot, (0.5, 0.45, 0.65)), ck.tcp_ik(robot, (-0.3, 0.5, 0.45))
    tool = ck.frame_positions(robot, goal[None], ck.TCP_FRAME)[0]
    probe = ck.CollisionWorld(
        robot, [ck.Obstacle.sphere(0.05, tool + np.array([0.0, 0.0, -0.3]), name="ball")]
    )
    gap = probe.clearance(goal).min_clearance_m  # the ball 30 cm under the tool, then moved up to 2 mm
    world = ck.CollisionWorld(
        robot, [ck.Obstacle.sphere(0.05, tool + np.array([0.0, 0.0, -0.3 + gap - 0.002]), name="ball")]
    )
    delta = goal - start

    def curve(t: np.ndarray) -> np.ndarray:
        return np.asarray(start + (3 * t**2 - 2 * t**3)[:, None] * delta)

    peak_speed, peak_acceleration = 1.5 * np.abs(delta), 6.0 * np.abs(delta)
    radii = ck.motion_radii(robot)

    def interval_speed(times: np.ndarray) -> np.ndarray:
        speed = (6 * times - 6 * times**2)[:, None] * np.abs(delta)
        rising = 0.5 * (speed[:-1] + speed[1:] + peak_acceleration * np.diff(times)[:, None])
        return np.asarray(np.minimum(rising, peak_speed) @ radii)

    uniform = ck.check_curve(world, curve, 0.0, 1.0, peak_speed, margin_m=0.0, step_m=0.005)
    local = ck.check_curve(world, curve, 0.0, 1.0, peak_speed, 0.0, 0.005, interval_speed)
    assert world.clearance(goal).min_clearance_m == pytest.approx(0.002, abs=1e-6)
    assert not uniform.accepted and local.accepted
    np.testing.assert_array_equal(uniform.times, local.times)  # the same samples, tighter bounds
    assert uniform.certified_min_m <= local.certified_min_m <= local.sampled_min_m
    dense = world.clearance_batch(curve(np.linspace(0.0, 1.0, 50 * len(local.times)))).min_clearance_m
    assert local.certified_min_m <= dense.min() + 1e-9


def test_a_stoppable_check_decides_as_one_that_is_not_until_stopped(
    rng: np.random.Generator,
) -> None:
    # a UR5 on its exact meshes among balls: the samples in doubt go to coal in pieces, with the
    # stop asked before each; never stopped, the check is the one-call check to the bit
    ur5 = ck.load_robot(example_robot("ur5"))
    balls = [ck.Obstacle.sphere(0.12, tuple(rng.uniform(-0.5, 0.5, 3)), name=f"ball{k}") for k in range(6)]
    world = ck.CollisionWorld(ur5, balls)
    assert ur5.exact_meshes
    a, b = random_configurations(ur5, rng, 2)

    def line(t: np.ndarray) -> np.ndarray:
        return np.asarray(a + np.asarray(t)[:, None] * (b - a))

    args = (world, line, 0.0, 1.0, np.abs(b - a), 0.01, 0.0005)
    plain = ck.check_curve(*args)
    asked, never = after_calls(10**9)
    stoppable = ck.check_curve(*args, stop=never)
    assert len(plain.times) > 4096 and len(asked) > 3  # in pieces
    for field in dataclasses.fields(plain):
        np.testing.assert_array_equal(getattr(stoppable, field.name), getattr(plain, field.name))
    asked, second = after_calls(1)
    with pytest.raises(ck.CheckStoppedError):
        ck.check_curve(*args, stop=second)
    assert len(asked) == 2


def test_lower_bounds_piece_by_piece_are_the_whole_batch(
    robot: ck.Robot, cluttered_world: ck.CollisionWorld, rng: np.random.Generator
) -> None:
    """The groups' bounds of a long check, reduced one piece at a time (its pairs' bounds, ``(K, P)``,
    never whole), are those of one call; the stop is asked before each piece."""
    from cpr_kin.certified.motion import LOWER_BOUND_ROWS, group_lower_bounds

    q = random_configurations(robot, rng, 2 * LOWER_BOUND_ROWS + 17)
    whole = cluttered_world.clearance_lower_bounds(q)
    asked, never = after_calls(10**9)
    np.testing.assert_array_equal(group_lower_bounds(cluttered_world, q, never), whole)
    assert len(asked) == 3
    np.testing.assert_array_equal(group_lower_bounds(cluttered_world, q), whole)
    assert group_lower_bounds(cluttered_world, q[:0]).shape == (0, len(ck.GROUPS))
