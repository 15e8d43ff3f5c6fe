"""MoveIt files in: MoveIt's shape conventions, poses, the allowed-collision matrix, goals and refusals.

The files are written here in MoveIt's YAML for example-robot-data's Panda; the
MotionBenchMaker set (downloaded from PyPI, cached) is converted whole in the slow test.
"""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

import cpr_kin as ck
from cpr_kin.model.packages import example_robot, example_robot_data_share
from planning.cli import main
from planning.io.moveit_objects import CONE_SIDES
from planning.io.moveit_state import wrapped
from planning.io.scene_file import load_scene
from planning.pipeline.planner import plan

PANDA = example_robot("panda")
PANDA_SRDF = PANDA.parent.parent / "srdf" / "panda.srdf"
READY = [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]
JOINTS = [f"panda_joint{k}" for k in range(1, 8)]

SCENE: dict[str, Any] = {
    "name": "shelf",
    "robot_state": {"joint_state": {"name": [*JOINTS, "panda_finger_joint1"], "position": [*READY, 0.03]}},
    "allowed_collision_matrix": {
        "entry_names": ["panda_link0", "panda_link1", "post"],
        "entry_values": [[False, True, False], [True, False, False], [False, False, False]],
    },
    "world": {
        "collision_objects": [
            {
                "id": "post",
                "header": {"frame_id": "panda_link0"},
                "pose": {"position": [0.5, 0.3, 0.0], "orientation": [0, 0, 0.3826834, 0.9238795]},
                "primitives": [
                    {"type": "box", "dimensions": [0.1, 0.2, 0.6]},
                    {"type": 3, "dimensions": [0.4, 0.05]},
                ],
                "primitive_poses": [
                    {
                        "position": {"x": 0.0, "y": 0.0, "z": 0.3},
                        "orientation": {"x": 0, "y": 0, "z": 0, "w": 1},
                    },
                    {"position": [0.0, 0.2, 0.4], "orientation": [0.7071068, 0, 0, 0.7071068]},
                ],
            },
            {
                "id": "lamp",
                "primitives": [
                    {"type": "sphere", "dimensions": [0.07]},
                    {"type": "cone", "dimensions": [0.2, 0.1]},
                ],
                "primitive_poses": [{"position": [0.3, -0.4, 0.9]}, {"position": [-0.3, -0.4, 0.9]}],
            },
        ]
    },
}
REQUEST: dict[str, Any] = {
    "group_name": "arm",
    "start_state": {"joint_state": {"name": JOINTS, "position": READY}},
    "goal_constraints": [
        {
            "joint_constraints": [
                {"joint_name": n, "position": v} for n, v in zip(JOINTS, [1.0, *READY[1:]], strict=True)
            ]
        }
    ],
    "planner_id": "RRTConnect",
    "allowed_planning_time": 5.0,
}


def write(folder: Path, scene: dict[str, Any], request: dict[str, Any]) -> list[str]:
    (folder / "scene.yaml").write_text(yaml.safe_dump(scene))
    (folder / "request.yaml").write_text(yaml.safe_dump(request))
    return [
        str(folder / "scene.yaml"),
        str(folder / "request.yaml"),
        "--urdf",
        str(PANDA),
        "--srdf",
        str(PANDA_SRDF),
    ]


def transform(position: list[float], quaternion_xyzw: list[float]) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = Rotation.from_quat(quaternion_xyzw).as_matrix()
    matrix[:3, 3] = position
    return matrix


def test_shapes_poses_and_the_matrix_follow_moveits_conventions(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out" / "shelf.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, REQUEST), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "4 obstacle(s), 7 planned joints, a 'q' goal, 1 allowed link pair(s)" in printed
    assert "left out or adjusted: request.planner_id" in printed  # said
    assert "allowed_planning_time" not in printed
    scene = load_scene(out)
    assert scene.planner.time_limit_s == 5.0  # MoveIt's allowed_planning_time
    box, cylinder, sphere, cone = scene.obstacles
    assert [o.name for o in scene.obstacles] == ["post_0", "post_1", "lamp_0", "lamp_1"]
    np.testing.assert_allclose(np.asarray(box.size), np.array([0.1, 0.2, 0.6]))
    assert (cylinder.shape, cylinder.length, cylinder.radius) == ("cylinder", 0.4, 0.05)  # [height, radius]
    assert sphere.radius == 0.07 and cone.shape == "mesh" and cone.convex
    # poses: the primitive's relative to the object's, checked with scipy's rotations
    post = transform([0.5, 0.3, 0.0], [0, 0, 0.3826834, 0.9238795])
    for obstacle, relative in (
        (box, transform([0, 0, 0.3], [0, 0, 0, 1])),
        (cylinder, transform([0, 0.2, 0.4], [0.7071068, 0, 0, 0.7071068])),
    ):
        expected = post @ relative
        np.testing.assert_allclose(obstacle.xyz, expected[:3, 3], atol=1e-9)
        placed = Rotation.from_euler("xyz", obstacle.rpy).as_matrix()  # roll-pitch-yaw about fixed axes
        np.testing.assert_allclose(placed, expected[:3, :3], atol=1e-6)
    # the cone's pyramid contains the cone: its base circle lies inside every side
    import trimesh

    pyramid = trimesh.load(cone.mesh)
    assert isinstance(pyramid, trimesh.Trimesh)
    assert len(pyramid.vertices) == CONE_SIDES + 1
    circle = np.column_stack(
        [
            0.1 * np.cos(np.linspace(0, 2 * np.pi, 500)),
            0.1 * np.sin(np.linspace(0, 2 * np.pi, 500)),
            np.full(500, -0.1),
        ]
    )
    assert (pyramid.nearest.signed_distance(circle) >= -1e-9).all()  # type: ignore[no-untyped-call]
    assert scene.allowed_collisions == (("panda_link0", "panda_link1"),)
    assert scene.start.q == dict(zip(JOINTS, READY, strict=True)) and scene.robot is not None
    assert dict(scene.robot.held) == {"panda_finger_joint1": 0.03}  # the hand as the state gives it
    assert (
        scene.safety_margin == 0.0 and isinstance(scene.goal.q, dict) and scene.goal.q["panda_joint1"] == 1.0
    )


def test_the_imported_scene_plans_and_passes_check(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene_file = tmp_path / "shelf.yaml"
    assert (
        main(
            [
                "import-moveit",
                *write(tmp_path, SCENE, REQUEST),
                "--safety-margin",
                "0.02",
                "--out",
                str(scene_file),
            ]
        )
        == 0
    )
    assert main(["plan", str(scene_file), "--out", str(tmp_path / "plan")]) == 0, capsys.readouterr().err
    assert main(["check", str(scene_file), str(tmp_path / "plan" / "trajectory.json")]) == 0


def test_a_pose_goal_becomes_a_pose_with_the_regions_tolerance(tmp_path: Path) -> None:
    request = copy.deepcopy(REQUEST)
    request["goal_constraints"] = [
        {
            "position_constraints": [
                {
                    "link_name": "panda_hand_tcp",
                    "constraint_region": {
                        "primitives": [{"type": 2, "dimensions": [0.002]}],
                        "primitive_poses": [{"position": [0.4, 0.2, 0.4]}],
                    },
                }
            ],
            "orientation_constraints": [
                {
                    "link_name": "panda_hand_tcp",
                    "orientation": [1, 0, 0, 0],
                    "absolute_x_axis_tolerance": 0.02,
                    "absolute_y_axis_tolerance": 0.01,
                    "absolute_z_axis_tolerance": 0.03,
                }
            ],
        }
    ]
    out = tmp_path / "pose.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(out)]) == 0
    scene = load_scene(out)
    assert scene.robot is not None and scene.robot.tcp == "panda_hand_tcp"
    assert (
        scene.goal.pose is not None and scene.goal.tolerance_m == 0.002 and scene.goal.tolerance_rad == 0.01
    )
    np.testing.assert_allclose(scene.goal.pose[1], np.diag([1.0, -1.0, -1.0]), atol=1e-12)


def test_a_value_a_hair_beyond_its_range_is_moved_onto_it_and_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    request = changed(REQUEST, "start_state.joint_state.position", [2.89735, *READY[1:]])  # range +-2.8973
    out = tmp_path / "edge.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(out)]) == 0
    assert "panda_joint1 = 2.89735 moved onto its range [-2.8973, 2.8973]" in capsys.readouterr().out
    start = load_scene(out).start.q
    assert isinstance(start, dict) and start["panda_joint1"] == 2.8973


def test_without_an_srdf_the_default_joints_load_with_the_package_dirs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robots = example_robot("xarm7").parents[2]
    text = (
        example_robot("xarm7")
        .read_text()
        .replace("package://example-robot-data/robots/", "package://my_arms/")
    )
    (tmp_path / "urdf").mkdir()
    (tmp_path / "urdf" / "xarm7.urdf").write_text(text)
    (tmp_path / "share").mkdir()
    (tmp_path / "share" / "my_arms").symlink_to(robots)
    joints = [f"joint{k}" for k in range(1, 8)]
    scene = {"world": {"collision_objects": [SCENE["world"]["collision_objects"][1]]}}
    request = {
        "start_state": {"joint_state": {"name": joints, "position": [0.0] * 7}},
        "goal_constraints": [{"joint_constraints": [{"joint_name": n, "position": 0.3} for n in joints]}],
    }
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene))
    (tmp_path / "request.yaml").write_text(yaml.safe_dump(request))
    files = [
        str(tmp_path / "scene.yaml"),
        str(tmp_path / "request.yaml"),
        "--urdf",
        str(tmp_path / "urdf" / "xarm7.urdf"),
    ]
    out = tmp_path / "xarm.yaml"
    assert (
        main(["import-moveit", *files, "--package-dir", str(tmp_path / "share"), "--out", str(out)]) == 0
    ), capsys.readouterr().err
    loaded = load_scene(out)
    assert loaded.robot is not None and loaded.robot.joints == tuple(joints)


@pytest.mark.parametrize(
    ("option", "name", "message"),
    [
        ("--package-dir", "nowhere", "package folder '{path}' (packages, for URDF"),
        ("--limits", "nowhere.yaml", "joint limits file '{path}' does not exist"),
    ],
)
def test_a_robot_file_that_is_not_there_is_named_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], option: str, name: str, message: str
) -> None:
    # the SRDF's group gives the joints without loading the robot: these were written into
    # the scene file, and only planning it named them
    out, missing = tmp_path / "out.yaml", tmp_path / name
    arguments = [*write(tmp_path, SCENE, REQUEST), option, str(missing), "--out", str(out)]
    assert main(["import-moveit", *arguments]) == 2
    error = capsys.readouterr().err
    assert message.format(path=missing) in error and len(error.strip().splitlines()) == 1
    assert not out.exists()


def changed(document: dict[str, Any], dotted: str, value: Any) -> dict[str, Any]:
    document = copy.deepcopy(document)
    *parents, last = dotted.split(".")
    target: Any = document
    for key in parents:
        target = target[int(key)] if isinstance(target, list) else target[key]
    target[last] = value
    return document


REFUSALS = [
    (
        "scene",
        "robot_state.attached_collision_objects",
        [{"link_name": "panda_hand"}],
        "robot_state.attached_collision_objects[0].object: required key is missing",
    ),
    ("scene", "world.collision_objects.0.planes", [{"coef": [0, 0, 1, 0]}], "planes are not supported"),
    ("scene", "world.collision_objects.0.operation", 1, "operation = 1; only ADD (0)"),
    ("scene", "world.collision_objects.1.primitives.0.dimensions", [0.1, 0.2], "a sphere needs 1 ([radius])"),
    (
        "scene",
        "world.collision_objects.0.header.frame_id",
        "camera",
        "world.collision_objects[0] ('post').header.frame_id: frame 'camera' is not known; the frames "
        "fixed to the world here: 'panda_link0'",
    ),
    (
        "scene",
        "world.colision_objects",
        [],
        "world.colision_objects: unknown key; allowed here: collision_objects, octomap",
    ),
    (  # the keys allowed are those of the nested message the key is in
        "scene",
        "world.collision_objects.0.primitive_posez",
        [],
        "world.collision_objects[0].primitive_posez: unknown key; allowed here: header, pose, id, type",
    ),
    (
        "scene",
        "world.collision_objects.0.primitives.0.dimensions",
        [0.1, 0.2, 500.0],
        "scene.world.collision_objects[0] ('post').primitives[0].dimensions[2] = 500.0: a box's [x, y, z] "
        "must each be in [0.0001, 100] m",
    ),
    (
        "request",
        "max_velocity_scaling_factor",
        0.1,
        "max_velocity_scaling_factor = 0.1: scaling is not supported",
    ),
    (
        "request",
        "path_constraints",
        {"joint_constraints": [{"joint_name": "panda_joint1", "position": 0.0}]},
        "path_constraints is not supported",
    ),
    ("request", "goal_constraints", [], "goal_constraints holds 0 sets; exactly one"),
    ("request", "group_name", "legs", "has no group 'legs'; its groups: ['arm', 'arm_and_hand', 'hand']"),
    ("request", "start_state.joint_state.name", JOINTS[:6], "has 6 names and 7 positions"),
]


@pytest.mark.parametrize(("which", "key", "value", "message"), REFUSALS, ids=[r[1] for r in REFUSALS])
def test_what_has_no_counterpart_is_refused_by_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], which: str, key: str, value: Any, message: str
) -> None:
    scene = changed(SCENE, key, value) if which == "scene" else SCENE
    request = changed(REQUEST, key, value) if which == "request" else REQUEST
    out = tmp_path / "out.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, request), "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert message in error and "Traceback" not in error and len(error.strip().splitlines()) == 1
    assert not out.exists() and not (tmp_path / "out_meshes").exists()


@pytest.mark.slow
def test_motionbenchmakers_problems_convert_and_are_valid_on_the_exact_meshes(tmp_path: Path) -> None:
    """A seeded sample of the Panda's and the UR5's problems (vamp-planner 0.6.4, from PyPI), 10 a class.

    Every one converts and its start and goal are valid on the exact meshes (the UR5's concave
    forearm refused some on its hulls). The full sets, 700 a robot: ``make import-mbm``, whose
    figures docs/benchmarks.md gives. One process per robot, side by side.
    """
    import subprocess
    import sys

    script = Path(__file__).resolve().parents[1] / "scripts" / "import_mbm.py"
    sample = ["--limit", "10", "--sample-seed", "1"]
    runs = {
        robot: subprocess.Popen(
            [sys.executable, str(script), "--robots", robot, *sample, "--out", str(tmp_path)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for robot in ("panda", "ur5")
    }
    outputs = {robot: run.communicate(timeout=900) for robot, run in runs.items()}
    for robot, run in runs.items():
        assert run.returncode == 0, outputs[robot][1]
        counts = next(line.split() for line in outputs[robot][0].splitlines() if line.startswith("all "))
        assert counts[1:4] == ["70", "70", "70"], outputs[robot][0]  # problems, converted, valid
        assert len(list((tmp_path / robot).glob("*.yaml"))) == 70


# Hostile files (issue 73): each the exact input, refused with exit 2 naming the field, or
# converted as MoveIt reads it and said.


def test_an_orientation_of_all_zeros_is_the_identity_and_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = changed(SCENE, "world.collision_objects.0.pose.orientation", [0, 0, 0, 0])
    scene = changed(
        scene, "world.collision_objects.0.primitive_poses.0.orientation", {"x": 0, "y": 0, "z": 0}
    )
    out = tmp_path / "zero.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "scene.world.collision_objects[0].pose.orientation of all zeros read as the identity" in printed
    box = load_scene(out).obstacles[0]
    np.testing.assert_allclose(box.xyz, [0.5, 0.3, 0.3], atol=1e-12)  # the object's pose unrotated
    np.testing.assert_allclose(box.rpy, [0.0, 0.0, 0.0], atol=1e-12)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        (
            "world.collision_objects.0.pose.orientation",
            [0.9, 0.9, 0, 0],
            "world.collision_objects[0].pose.orientation = [0.9, 0.9, 0, 0]: has norm 1.27279",
        ),
        (
            "world.collision_objects.0.pose.orientation",
            {"x": 1, "y": 0, "z": 0},
            "gives no w: ROS 1 reads it as 0, ROS 2 as 1",
        ),
        (
            "world.collision_objects.0.primitives.0.dimensions",
            ["0.1", 0.2, 0.6],
            "dimensions[0] = '0.1': Input should be a valid number",
        ),
        (
            "allowed_collision_matrix.entry_values",
            [["yes", True, False], [True, False, False], [False, False, False]],
            "entry_values[0][0] = 'yes': Input should be a valid boolean",
        ),
        (
            "world.collision_objects.0.primitives.0.dimensions",
            [0.1, -0.05, 0.6],
            "scene.world.collision_objects[0] ('post').primitives[0].dimensions[1] = -0.05: a box's",
        ),
        (
            "world.collision_objects.1.primitive_poses.0.position",
            [300.0, 0.0, 0.0],
            "scene.world.collision_objects[1] ('lamp').primitives[0]: placed at [300.0, 0.0, 0.0] m",
        ),
    ],
)
def test_a_hostile_scene_is_refused_naming_the_input_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, value: Any, message: str
) -> None:
    out = tmp_path / "o" / "m10.yaml"
    assert (
        main(["import-moveit", *write(tmp_path, changed(SCENE, key, value), REQUEST), "--out", str(out)]) == 2
    )
    error = capsys.readouterr().err
    assert message in error and "m10.yaml" not in error and len(error.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_an_empty_file_is_refused_and_a_scene_without_objects_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    arguments = write(tmp_path, {"robot_state": SCENE["robot_state"]}, REQUEST)
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / "free.yaml")]) == 0
    said = "no collision objects and no octomap in the PlanningScene: the scene has no obstacles"
    assert said in capsys.readouterr().out
    (tmp_path / "scene.yaml").write_text("# nothing\n")
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / "none.yaml")]) == 2
    assert "PlanningScene file" in capsys.readouterr().err and not (tmp_path / "none.yaml").exists()


@pytest.mark.parametrize("which", ["scene", "request", "limits", "symlink", "hardlink"])
def test_an_output_that_is_an_input_is_refused_and_the_input_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], which: str
) -> None:
    urdf = tmp_path / "panda.urdf"
    urdf.write_text(PANDA.read_text().replace("package://example-robot-data/robots/", f"{PANDA.parents[2]}/"))
    (tmp_path / "limits.yaml").write_text("panda_joint1: {acceleration: 10, jerk: 100}\n")
    arguments = [*write(tmp_path, SCENE, REQUEST), "--limits", str(tmp_path / "limits.yaml")]
    arguments[arguments.index("--urdf") + 1] = str(urdf)
    (tmp_path / "symlink.yaml").symlink_to(tmp_path / "scene.yaml")  # the scene, by another name
    (tmp_path / "hardlink.yaml").hardlink_to(urdf)  # the URDF, by another name
    out = f"{which}.yaml"
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / out)]) == 2
    assert "an input of this command" in capsys.readouterr().err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def request_with_goal_in(frame: str, fixed: list[dict[str, Any]] | None = None) -> dict[str, Any]:
    request = copy.deepcopy(REQUEST)
    request["goal_constraints"] = [
        {
            "position_constraints": [
                {
                    "header": {"frame_id": frame},
                    "link_name": "panda_hand_tcp",
                    "constraint_region": {
                        "primitives": [{"type": 2, "dimensions": [0.002]}],
                        "primitive_poses": [{"position": [0.1, 0.2, 0.3]}],
                    },
                }
            ],
            "orientation_constraints": [
                {
                    "header": {"frame_id": frame},
                    "link_name": "panda_hand_tcp",
                    "orientation": [1, 0, 0, 0],
                    "absolute_x_axis_tolerance": 0.01,
                    "absolute_y_axis_tolerance": 0.01,
                    "absolute_z_axis_tolerance": 3.14,
                }
            ],
        }
    ]
    return request


def test_a_goal_in_a_world_fixed_frame_is_moved_into_the_base(tmp_path: Path) -> None:
    # a frame of fixed_frame_transforms, and an object's frame: the goal pose is T @ pose,
    # checked with scipy's rotations
    table = {"header": {"frame_id": "panda_link0"}, "child_frame_id": "table"}
    table["transform"] = {"translation": [0.4, -0.1, 0.05], "rotation": [0, 0, 0.3826834, 0.9238795]}
    scene = {**SCENE, "fixed_frame_transforms": [table]}
    for frame, frame_in_base in (
        ("table", transform([0.4, -0.1, 0.05], [0, 0, 0.3826834, 0.9238795])),
        ("post", transform([0.5, 0.3, 0.0], [0, 0, 0.3826834, 0.9238795])),
        ("", np.eye(4)),
    ):
        out = tmp_path / f"goal_{frame}.yaml"
        assert (
            main(["import-moveit", *write(tmp_path, scene, request_with_goal_in(frame)), "--out", str(out)])
            == 0
        )
        goal = load_scene(out).goal
        assert goal.pose is not None
        expected = frame_in_base @ transform([0.1, 0.2, 0.3], [1, 0, 0, 0])
        np.testing.assert_allclose(goal.pose[0], expected[:3, 3], atol=1e-7)
        np.testing.assert_allclose(np.array(goal.pose[1]), expected[:3, :3], atol=1e-6)


@pytest.mark.parametrize(
    ("frame", "message"),
    [
        ("panda_link7", "frame 'panda_link7' is a link that joint 'panda_joint1' moves"),
        ("camera_link", "frame 'camera_link' is not known; the frames fixed to the world here:"),
    ],
)
def test_a_goal_in_a_moving_or_unknown_frame_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], frame: str, message: str
) -> None:
    out = tmp_path / "goal.yaml"
    assert (
        main(["import-moveit", *write(tmp_path, SCENE, request_with_goal_in(frame)), "--out", str(out)]) == 2
    )
    error = capsys.readouterr().err
    assert "request.goal_constraints[0].position_constraints[0].header.frame_id" in error and message in error
    assert not out.exists()


def test_a_position_goal_in_a_box_becomes_a_tool_point_within_the_boxs_inscribed_sphere(
    tmp_path: Path,
) -> None:
    # no orientation constraint: a tcp goal; the box's half shortest side is the tolerance, and
    # the region's centre is moved from the post's frame into the base (checked with scipy's rotations)
    request = request_with_goal_in("post")
    goal = request["goal_constraints"][0]
    del goal["orientation_constraints"]
    region = goal["position_constraints"][0]["constraint_region"]
    region["primitives"] = [{"type": "box", "dimensions": [0.010, 0.004, 0.006]}]
    out = tmp_path / "point.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(out)]) == 0
    scene = load_scene(out)
    assert scene.robot is not None and scene.robot.tcp == "panda_hand_tcp"
    assert scene.goal.pose is None and scene.goal.tolerance_m == pytest.approx(0.002, abs=1e-15)
    centre = transform([0.5, 0.3, 0.0], [0, 0, 0.3826834, 0.9238795]) @ [0.1, 0.2, 0.3, 1.0]
    assert scene.goal.tcp is not None
    np.testing.assert_allclose(scene.goal.tcp, centre[:3], atol=1e-7)


GOAL = "goal_constraints.0"
POSITION = f"{GOAL}.position_constraints.0"
GOAL_REFUSALS = [
    (
        f"{GOAL}.joint_constraints",
        [{"joint_name": "panda_joint1", "position": 0.0}],
        "a goal of joint and pose constraints together is not supported",
    ),
    (f"{GOAL}.visibility_constraints", [{"target_radius": 0.1}], "visibility_constraints are not supported"),
    (
        f"{GOAL}.position_constraints",
        [],
        "has 0 position and 1 orientation constraints; supported: one position constraint",
    ),
    (f"{POSITION}.target_point_offset", [0.0, 0.0, 0.1], "needs a zero target_point_offset"),
    (
        f"{POSITION}.constraint_region.primitives",
        [{"type": 3, "dimensions": [0.1, 0.01]}],
        "type 3 with dimensions [0.1, 0.01]; a goal region must be a sphere (2, [radius]) or a box",
    ),
    (
        f"{POSITION}.constraint_region.primitives",
        [{"type": "box", "dimensions": [0.01, 0.0, 0.01]}],
        "a box's sides must be > 0 m",
    ),
    (
        f"{GOAL}.orientation_constraints.0.link_name",
        "panda_hand",
        "link_name = 'panda_hand' differs from the position constraint's 'panda_hand_tcp'",
    ),
]


@pytest.mark.parametrize(("key", "value", "message"), GOAL_REFUSALS, ids=[r[0] for r in GOAL_REFUSALS])
def test_a_goal_without_a_scene_counterpart_is_refused_by_name(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], key: str, value: Any, message: str
) -> None:
    request = changed(request_with_goal_in("panda_link0"), key, value)
    out = tmp_path / "goal.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert "request.goal_constraints[0]" in error and message in error
    assert "Traceback" not in error and len(error.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize(
    ("joints", "message"),
    [
        (JOINTS[:6], "missing ['panda_joint7'], not planned []"),
        ([*JOINTS, "panda_finger_joint1"], "missing [], not planned ['panda_finger_joint1']"),
        ([*JOINTS, "panda_joint3"], "constrain ['panda_joint3'] more than once; each joint once"),
    ],
)
def test_a_joint_goal_names_each_planned_joint_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], joints: list[str], message: str
) -> None:
    request = changed(
        REQUEST,
        "goal_constraints.0.joint_constraints",
        [{"joint_name": name, "position": 0.0} for name in joints],
    )
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(tmp_path / "g.yaml")]) == 2
    error = capsys.readouterr().err
    assert "request.goal_constraints[0].joint_constraints" in error and message in error


def test_a_goal_region_with_a_negative_radius_names_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    request = changed(
        request_with_goal_in("panda_link0"),
        "goal_constraints.0.position_constraints.0.constraint_region.primitives.0.dimensions",
        [-0.1],
    )
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(tmp_path / "g.yaml")]) == 2
    assert (
        "constraint_region.primitives[0].dimensions = [-0.1]: a sphere's radius must be > 0 m"
        in capsys.readouterr().err
    )


def test_a_wide_yaw_tolerance_is_narrowed_and_said(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    request = changed(
        request_with_goal_in("panda_link0"),
        "goal_constraints.0.orientation_constraints.0.absolute_x_axis_tolerance",
        3.14,
    )
    request = changed(request, "goal_constraints.0.orientation_constraints.0.absolute_y_axis_tolerance", 3.14)
    out = tmp_path / "wide.yaml"
    assert main(["import-moveit", *write(tmp_path, SCENE, request), "--out", str(out)]) == 0
    assert "orientation tolerance 3.14 rad narrowed to 0.5 rad" in capsys.readouterr().out
    assert load_scene(out).goal.tolerance_rad == 0.5


def test_mimic_joints_of_the_start_state_follow_their_leader(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the state gives both fingers, the second a value its <mimic> contradicts: MoveIt sets it
    # from the first, and so does the scene (fixed: holds the leader only)
    scene = changed(
        SCENE, "robot_state.joint_state.name", [*JOINTS, "panda_finger_joint1", "panda_finger_joint2"]
    )
    scene = changed(scene, "robot_state.joint_state.position", [*READY, 0.03, 0.01])
    out = tmp_path / "fingers.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    assert "mimic joint(s) ['panda_finger_joint2']" in capsys.readouterr().out
    loaded = load_scene(out)
    assert loaded.robot is not None and dict(loaded.robot.held) == {"panda_finger_joint1": 0.03}


@pytest.mark.parametrize(
    ("count", "message"),
    [
        (600, "scene.world.collision_objects make 600 obstacles; a scene holds at most 500"),
        (20_000, "more than 100000 values (numbers, strings, lists, mappings); at most 100000 are read"),
    ],
)
def test_too_many_objects_are_refused_saying_the_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], count: int, message: str
) -> None:
    arguments = write(tmp_path, SCENE, REQUEST)
    box = (
        "  - {{id: box{}, primitives: [{{type: 1, dimensions: [0.1, 0.1, 0.1]}}], "
        "primitive_poses: [{{position: [1, 1, 1]}}]}}\n"
    )
    (tmp_path / "scene.yaml").write_text(
        "world:\n collision_objects:\n" + "".join(box.format(k) for k in range(count))
    )
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / "many.yaml")]) == 2
    assert message in capsys.readouterr().err and not (tmp_path / "many.yaml").exists()


@pytest.mark.parametrize(
    ("which", "key", "value", "message"),
    [
        (
            "scene",
            "world.collision_objects.1.id",
            "post",
            "collision_objects[0] has the same id; ids must be unique",
        ),
        ("scene", "world.collision_objects.1.id", "", "collision_objects[1] ('').id must be 1-96 printable"),
        (
            "scene",
            "robot_state.joint_state.name",
            [*JOINTS[:6], "panda_joint1", "panda_finger_joint1"],
            "joint_state.name gives ['panda_joint1'] more than once",
        ),
        (
            "request",
            "goal_constraints.0.joint_constraints.6.joint_name",
            "panda_joint1",
            "joint_constraints constrain ['panda_joint1'] more than once",
        ),
    ],
)
def test_names_given_twice_or_not_at_all_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], which: str, key: str, value: Any, message: str
) -> None:
    scene = changed(SCENE, key, value) if which == "scene" else SCENE
    request = changed(REQUEST, key, value) if which == "request" else REQUEST
    assert main(["import-moveit", *write(tmp_path, scene, request), "--out", str(tmp_path / "o.yaml")]) == 2
    assert message in capsys.readouterr().err and not (tmp_path / "o.yaml").exists()


def test_an_object_id_that_is_a_path_names_a_mesh_file_inside_the_mesh_folder(tmp_path: Path) -> None:
    scene = changed(SCENE, "world.collision_objects.1.id", "../../escaped")  # the lamp's cone is a mesh
    out = tmp_path / "deep" / "er" / "s.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    assert sorted(p.name for p in (out.parent / "s_meshes").iterdir()) == ["_.._escaped_1.stl"]
    assert not list(tmp_path.glob("escaped*")) and load_scene(out).obstacles[3].name == "../../escaped_1"


def test_an_output_that_cannot_be_written_leaves_no_mesh(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "s.yaml"
    out.mkdir()  # a folder where the scene file goes: the meshes were left behind
    assert main(["import-moveit", *write(tmp_path, SCENE, REQUEST), "--out", str(out)]) == 2
    assert "is a folder; give a file name" in capsys.readouterr().err
    assert not (tmp_path / "s_meshes").exists()


def test_ros1_frames_and_the_srdfs_world_are_known(tmp_path: Path) -> None:
    srdf = tmp_path / "panda.srdf"
    srdf.write_text(
        PANDA_SRDF.read_text().replace(
            "</robot>",
            '<virtual_joint name="v" type="fixed" parent_frame="world" child_link="panda_link0"/></robot>',
        )
    )
    scene = changed(SCENE, "world.collision_objects.0.header.frame_id", "/world")  # ROS 1's leading slash
    arguments = write(tmp_path, scene, request_with_goal_in("/panda_link0"))
    arguments[arguments.index("--srdf") + 1] = str(srdf)
    out = tmp_path / "world.yaml"
    assert main(["import-moveit", *arguments, "--out", str(out)]) == 0
    np.testing.assert_allclose(load_scene(out).obstacles[0].xyz, [0.5, 0.3, 0.3], atol=1e-6)


def test_a_group_name_without_an_srdf_is_said(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    arguments = write(tmp_path, SCENE, REQUEST)[:-2]  # no --srdf
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / "o.yaml")]) == 0
    assert "request.group_name 'arm' (no SRDF to look it up in): planned (" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (["--safety-margin", "-1"], "--safety-margin = -1.0 m must be a number in [0, 1] m"),
        (["--self-margin", "nan"], "--self-margin = nan m must be a number in [0, 1] m"),
        (
            ["--limits", str(PANDA)],
            "must map joint names to limits ({joint: {acceleration: ..., jerk: ...}}), not str",
        ),
        (["--out-suffix", ".json"], "must end in .yaml or .yml: a scene file is YAML"),
    ],
)
def test_bad_options_are_named_by_their_flag(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], options: list[str], message: str
) -> None:
    out = tmp_path / ("converted" + (options[1] if options[0] == "--out-suffix" else ".yaml"))
    extra = [] if options[0] == "--out-suffix" else options
    assert main(["import-moveit", *write(tmp_path, SCENE, REQUEST), *extra, "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1 and not out.exists()


def test_a_scene_of_another_robot_model_is_said(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = {**SCENE, "robot_model_name": "ur5_robotiq85"}  # MoveIt warns and applies it
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(tmp_path / "o.yaml")]) == 0
    assert "scene.robot_model_name 'ur5_robotiq85' is not the URDF's robot 'panda'" in capsys.readouterr().out


PART: dict[str, Any] = {  # a part held between the Panda's fingers, sticking out below them
    "link_name": "panda_hand",
    "object": {
        "id": "part",
        "header": {"frame_id": "panda_hand"},
        "primitives": [{"type": 1, "dimensions": [0.02, 0.02, 0.08]}],
        "primitive_poses": [{"position": [0.0, 0.0, 0.12]}],
    },
    "touch_links": ["panda_leftfinger", "panda_rightfinger"],
    "weight": 0.4,
}


def test_links_the_matrix_lets_touch_a_world_object_are_its_obstacles_touch_links(tmp_path: Path) -> None:
    scene = changed(  # panda_link0 may touch the post: both of its primitives' obstacles say so
        SCENE,
        "allowed_collision_matrix.entry_values",
        [[False, True, True], [True, False, False], [True, False, False]],
    )
    out = tmp_path / "touch.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    touching = {o.name: o.touch_links for o in load_scene(out).obstacles}
    assert touching == {"post_0": ("panda_link0",), "post_1": ("panda_link0",), "lamp_0": (), "lamp_1": ()}
    scene_read = load_scene(out)
    robot = scene_read.robot_spec().load()
    link = {g.name: g.link for g in robot.geometries}
    checked = {(link[g], o) for g, o, _ in ck.CollisionWorld(robot, scene_read.obstacles).pairs}
    assert ("panda_link0", "post_0") not in checked and ("panda_link0", "lamp_0") in checked
    assert ("panda_link1", "post_0") in checked
    # a link's default entry true: it may touch what the matrix has no entry with (the lamp), not the
    # post, whose entry with it says false (MoveIt's rule: the pair's entry comes first)
    scene = changed(scene, "allowed_collision_matrix.default_entry_names", ["panda_link1"])
    scene = changed(scene, "allowed_collision_matrix.default_entry_values", [True])
    out = tmp_path / "default.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    touching = {o.name: o.touch_links for o in load_scene(out).obstacles}
    assert touching == {
        "post_0": ("panda_link0",),
        "post_1": ("panda_link0",),
        "lamp_0": ("panda_link1",),
        "lamp_1": ("panda_link1",),
    }


def test_world_objects_the_attached_one_may_touch_are_the_payloads_touch_obstacles(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = changed(SCENE, "robot_state.attached_collision_objects", [PART])
    scene = changed(scene, "allowed_collision_matrix.entry_names", ["panda_link0", "post", "part"])
    scene = changed(
        scene,
        "allowed_collision_matrix.entry_values",
        [[False, False, False], [False, False, True], [False, True, False]],
    )
    out = tmp_path / "touching.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 0
    payload = load_scene(out).payload
    assert payload is not None and payload.touch_obstacles == ("post_0", "post_1")  # both of its shapes
    robot = load_scene(out).robot_spec().load()
    world = ck.CollisionWorld(ck.carrying(robot, payload), load_scene(out).obstacles)
    assert {(g, o) for g, o, _ in world.pairs if g == "part"} == {("part", "lamp_0"), ("part", "lamp_1")}
    capsys.readouterr()


def test_an_attached_object_becomes_the_payload_and_plans_certified(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = changed(SCENE, "robot_state.attached_collision_objects", [PART])
    scene = changed(scene, "allowed_collision_matrix.entry_names", ["panda_link0", "panda_link7", "part"])
    scene = changed(  # the matrix lets the part touch link 7 too: a touch link, as in MoveIt
        scene,
        "allowed_collision_matrix.entry_values",
        [[False, False, False], [False, False, True], [False, True, False]],
    )
    out = tmp_path / "carry.yaml"
    assert (
        main(
            ["import-moveit", *write(tmp_path, scene, REQUEST), "--safety-margin", "0.01", "--out", str(out)]
        )
        == 0
    )
    loaded = load_scene(out)
    payload = loaded.payload
    assert payload is not None and payload.shape is not None
    assert (payload.name, payload.frame, payload.mass_kg) == ("part", "panda_hand", 0.4)
    assert payload.touch_links == ("panda_leftfinger", "panda_link7", "panda_rightfinger")
    np.testing.assert_allclose(payload.com_in_frame_m, [0.0, 0.0, 0.12])
    np.testing.assert_allclose(np.asarray(payload.shape.size), [0.02, 0.02, 0.08])
    np.testing.assert_allclose(payload.shape.xyz, [0.0, 0.0, 0.12])
    plan = tmp_path / "plan"
    assert main(["plan", str(out), "--out", str(plan)]) == 0, capsys.readouterr().err
    assert main(["check", str(out), str(plan / "trajectory.json")]) == 0


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (
            lambda part: [part, {**part, "object": {**part["object"], "id": "second"}}],
            "2 attached objects ['part', 'second']; one is supported",
        ),
        (
            lambda part: [{**part, "object": {**part["object"], "header": {"frame_id": "panda_link0"}}}],
            "object.header.frame_id = 'panda_link0': give the attached object in its link's frame "
            "'panda_hand'",
        ),
        (lambda part: [{**part, "link_name": "gripper"}], "link_name = 'gripper' is not a link of the URDF"),
        (lambda part: [{**part, "weight": -1.0}], "weight = -1.0 kg must be in [0, 1000] kg"),
        (
            lambda part: [{**part, "touch_links": ["finger"]}],
            "touch_links ['finger'] are not links of the URDF",
        ),
    ],
)
def test_an_attached_object_that_does_not_fit_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: Any, message: str
) -> None:
    unshared = json.loads(json.dumps(change(PART)))  # no YAML anchors for shared parts
    scene = changed(SCENE, "robot_state.attached_collision_objects", unshared)
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(tmp_path / "o.yaml")]) == 2
    error = capsys.readouterr().err
    assert "attached_collision_objects" in error and message in error and not (tmp_path / "o.yaml").exists()


def test_an_attached_mesh_is_written_beside_the_scene_with_its_centroid_as_the_mass_centre(
    tmp_path: Path,
) -> None:
    import trimesh

    box = trimesh.creation.box(extents=(0.02, 0.02, 0.08))
    box.apply_translation([0.0, 0.0, 0.04])  # its centroid 4 cm above the mesh's origin
    mesh = {
        "vertices": box.vertices.tolist(),
        "triangles": [{"vertex_indices": f.tolist()} for f in box.faces],
    }
    part = copy.deepcopy(PART)
    part["object"] = {"id": "part", "meshes": [mesh], "mesh_poses": [{"position": [0.0, 0.0, 0.08]}]}
    out = tmp_path / "mesh.yaml"
    assert (
        main(
            [
                "import-moveit",
                *write(tmp_path, changed(SCENE, "robot_state.attached_collision_objects", [part]), REQUEST),
                "--out",
                str(out),
            ]
        )
        == 0
    )
    assert yaml.safe_load(out.read_text())["payload"]["shape"]["mesh"] == "mesh_meshes/part.stl"
    payload = load_scene(out).payload
    assert payload is not None and payload.shape is not None and payload.shape.shape == "mesh"
    np.testing.assert_allclose(payload.com_in_frame_m, [0.0, 0.0, 0.12], atol=1e-9)


def test_a_urdf_origin_that_is_not_three_numbers_is_named(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # read for the frames and ranges before the robot loads (the SRDF gives the joints): it was a
    # ValueError, exit 4; the URDF is now checked as the loader checks it first
    urdf = tmp_path / "panda.urdf"
    urdf.write_text(
        PANDA.read_text()
        .replace("package://example-robot-data/robots/", f"{PANDA.parents[2]}/")
        .replace('xyz="0 0 0.333"', 'xyz="0 0 zz"', 1)
    )
    arguments = write(tmp_path, SCENE, REQUEST)
    arguments[arguments.index("--urdf") + 1] = str(urdf)
    assert main(["import-moveit", *arguments, "--out", str(tmp_path / "o.yaml")]) == 2
    error = capsys.readouterr().err
    assert f"URDF file '{urdf}' cannot be read (ValueError: could not convert string to float: 'zz')" in error


def test_a_default_entry_yields_to_the_pairs_own_entry_as_in_moveit() -> None:
    from planning.io.moveit_matrix import AllowedContacts
    from planning.io.moveit_messages import AllowedCollisionMatrix

    matrix = AllowedCollisionMatrix(
        entry_names=["a", "b", "box"],
        entry_values=[[False, False, False], [False, False, True], [False, True, False]],
        default_entry_names=["a"],
        default_entry_values=[True],
    )
    links = {"a", "b", "c"}
    # a touches c (no entry: its default), not b (their entry says false); b touches the box (entry)
    contacts = AllowedContacts(matrix)
    assert contacts.link_pairs(links) == [["a", "c"]]
    assert contacts.allowed_with("box", links) == {"b"}
    assert contacts.allowed_with("ball", links) == {"a"}  # no entry with a: its default
    defaults = {"default_entry_names": ["a", "c"], "default_entry_values": [True, False]}
    never = matrix.model_copy(update=defaults)
    assert AllowedContacts(never).link_pairs(links) == []  # of two defaults, false wins


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_continuous_joints_goal_is_turned_to_within_half_a_turn_of_its_start(seed: int) -> None:
    # MoveIt plans a continuous joint the short way round: a goal at -3.0 rad from a start at
    # 3.0 rad was wrapped into [-pi, pi] alone and planned 6 rad round
    rng = np.random.default_rng(seed)
    start = {"c": float(rng.uniform(-math.pi, math.pi)), "r": 0.5}
    goal = {"c": float(rng.uniform(-20.0, 20.0)), "r": float(rng.uniform(-3.0, 3.0))}
    turned = wrapped(goal, {"c"}, start)
    assert turned["r"] == goal["r"]  # a revolute joint's value is as given
    assert abs(turned["c"] - start["c"]) <= math.pi + 1e-12  # the short way
    assert math.remainder(turned["c"] - goal["c"], math.tau) == pytest.approx(0.0, abs=1e-9)  # whole turns
    assert abs(turned["c"]) <= 2 * math.pi  # within the range it is planned in
    notes: list[str] = []
    assert wrapped({"c": 3.0}, {"c"}, {"c": -3.0}, notes) == {"c": pytest.approx(3.0 - math.tau)}
    assert notes == [
        "c = 3.0 turned by whole turns to -3.28319 rad, within pi of the start's -3 (a continuous "
        "joint: the same pose, the short way round)"
    ]
    assert wrapped({"c": 1.0}, {"c"}, {"c": 0.5}, notes) == {"c": 1.0} and len(notes) == 1  # unturned: unsaid


def test_a_continuous_joints_goal_across_pi_is_imported_and_planned_the_short_way(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Kinova's first joint is continuous: a goal constraint at -3.0 rad from a start at 3.0 rad
    # was wrapped alone into [-pi, pi] and planned 6 rad round; MoveIt turns it 0.28 rad
    share = example_robot_data_share()
    assert share is not None
    folder = share / "example-robot-data/robots/kinova_description"
    joints = [f"j2s6s200_joint_{k}" for k in range(1, 7)]
    start = [3.0, 2.9, 1.3, -2.0, 1.5, 0.5]
    request = {
        "group_name": "end_effector",
        "start_state": {"joint_state": {"name": joints, "position": start}},
        "goal_constraints": [
            {
                "joint_constraints": [
                    {"joint_name": n, "position": v} for n, v in zip(joints, [-3.0, *start[1:]], strict=True)
                ]
            }
        ],
    }
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump({"world": {"collision_objects": []}}))
    (tmp_path / "request.yaml").write_text(yaml.safe_dump(request))
    urdf, srdf = folder / "robots/kinova.urdf", folder / "srdf/kinova.srdf"
    out = tmp_path / "kinova.yaml"
    arguments = [str(tmp_path / "scene.yaml"), str(tmp_path / "request.yaml"), "--urdf", str(urdf)]
    assert main(["import-moveit", *arguments, "--srdf", str(srdf), "--out", str(out)]) == 0
    printed = capsys.readouterr().out  # said among what was adjusted
    assert (
        "j2s6s200_joint_1 = -3.0 turned by whole turns to 3.28319 rad, within pi of the start's 3" in printed
    )
    scene = load_scene(out)
    goal = scene.goal.q
    assert isinstance(goal, Mapping)
    assert goal["j2s6s200_joint_1"] == pytest.approx(-3.0 + 2 * math.pi)  # a whole turn on
    result = plan(scene)
    q = result.trajectory(np.linspace(0.0, result.trajectory.duration, 200))
    assert np.ptp(q[:, 0]) == pytest.approx(2 * math.pi - 6.0, abs=1e-6)  # the short way: 0.28 rad
