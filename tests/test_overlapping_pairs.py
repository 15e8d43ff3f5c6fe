"""Link pairs that collide in every configuration: found, left unchecked, named; no others."""

from __future__ import annotations

import numpy as np

import cpr_kin as ck
from cpr_kin.bounds.overlapping_pairs import overlapping_pairs
from cpr_kin.collision.self_collision import SelfCollision
from cpr_kin.model.packages import example_robot_data_share
from planning.bench.arm_scenes import blocked_scene
from planning.io.report import report_markdown
from planning.io.scene_file import parse_scene
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.verification import verify_for_scene

from .conftest import turning_balls

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"


def test_only_a_pair_that_collides_wherever_the_joint_turns_is_found() -> None:
    model, geometry_model, ids = turning_balls(
        {
            "hub": (False, 0.2, 0.0),  # on the axis: the turning balls stay 0.25 m and 0.5 m from it
            "inner": (True, 0.1, 0.25),
            "outer": (True, 0.1, 0.5),
            "post": (False, 0.05, 0.25),  # met by the inner ball only near angle 0
        }
    )
    hub, inner, outer, post = (ids[name] for name in ("hub", "inner", "outer", "post"))
    pairs = [(hub, inner), (hub, outer), (post, inner), (post, outer)]
    assert overlapping_pairs(model, geometry_model, pairs) == ((hub, inner),)
    assert overlapping_pairs(model, geometry_model, []) == ()


ALEX = {
    "urdf": str(ROBOTS / "alex_description" / "urdf" / "alex_nub_hands.urdf"),
    "tcp": "RightWristRollLink",
    "srdf": str(ROBOTS / "alex_description" / "srdf" / "alex_nub_hands.srdf"),
}


def test_alexs_spine_and_torso_overlap_and_go_unchecked() -> None:
    # Alex's SpineYawLink and Torso shapes overlap 6-27 mm across the spine's ranges, and its
    # SRDF does not disable them: every start was refused ("inside the self margin")
    robot = ck.load_robot(ALEX["urdf"], tcp=ALEX["tcp"], srdf=ALEX["srdf"])
    assert robot.overlapping_links == (("SpineYawLink", "Torso"),)
    links = [robot.model.frames[obj.parentFrame].name for obj in robot.collision_model.geometryObjects]
    checked = {frozenset((links[a], links[b])) for a, b in robot.self_pairs}
    assert frozenset(("SpineYawLink", "Torso")) not in checked and len(checked) > 100
    # on fresh configurations (another seed) the pair still overlaps everywhere, by coal's distance
    (pair,) = [
        (a, b)
        for a in range(len(links))
        for b in range(a + 1, len(links))
        if {links[a], links[b]} == {"SpineYawLink", "Torso"}
    ]
    names = [g.name for g in robot.geometries]
    alone = SelfCollision(robot.model, robot.collision_model, (pair,), names)
    q = np.random.default_rng(7).uniform(robot.limits.lower, robot.limits.upper, (200, robot.nq))
    assert np.all(alone.distances(q)[0] < 0.0)


def test_arms_that_plan_lose_no_pair() -> None:
    for urdf in ("panda_description/urdf/panda.urdf", "ur_description/urdf/ur5_robot.urdf"):
        robot = ck.load_robot(ROBOTS / urdf)
        assert robot.overlapping_links == ()
        assert len(robot.self_pairs) > 10


def test_alexs_arm_plans_and_its_report_names_the_pair() -> None:
    robot = ck.load_robot(ALEX["urdf"], tcp=ALEX["tcp"], srdf=ALEX["srdf"])
    scene = parse_scene(blocked_scene("alex_1103", ALEX, robot, 1103, self_clearance_m=0.015))
    result = plan(scene, robot)
    assert not verify_for_scene(build_problem(scene, robot), result.trajectory).problems  # `check`'s verdict
    assert (
        "not checked (MoveIt's setup assistant disables them as always in collision): SpineYawLink / Torso."
        in (report_markdown(result))
    )
