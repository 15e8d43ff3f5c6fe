"""MoveIt files in: MoveIt's shape conventions, poses, the allowed-collision matrix, goals and refusals.

The files are written here in MoveIt's YAML for example-robot-data's Panda; the
MotionBenchMaker set (downloaded from PyPI, cached) is converted whole in the slow test.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from scipy.spatial.transform import Rotation

from cpr_kin.packages import example_robot
from planning.cli import main
from planning.io.moveit_objects import CONE_SIDES
from planning.io.scene_file import load_scene

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
        "attached_collision_objects is not supported",
    ),
    ("scene", "world.collision_objects.0.planes", [{"coef": [0, 0, 1, 0]}], "planes are not supported"),
    ("scene", "world.collision_objects.0.operation", 1, "operation = 1; only ADD (0)"),
    ("scene", "world.collision_objects.1.primitives.0.dimensions", [0.1, 0.2], "a sphere needs 1 ([radius])"),
    (
        "scene",
        "world.collision_objects.0.header.frame_id",
        "camera",
        "frame 'camera' is not the robot's base",
    ),
    (
        "scene",
        "allowed_collision_matrix.entry_values",
        [[False, False, True], [False, False, False], [True, False, False]],
        "contact with an object is not supported",
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
        "obstacles[0].size[2] = 500.0",
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
def test_every_motionbenchmaker_problem_converts(tmp_path: Path) -> None:
    """The 700 Panda and 700 UR5 problems of vamp-planner 0.6.4 (from PyPI, cached): convert, and count.

    One process per robot, side by side (the script's own use, robot by robot, on two cores).
    """
    import subprocess
    import sys

    script = Path(__file__).resolve().parents[1] / "scripts" / "import_mbm.py"
    runs = {
        robot: subprocess.Popen(
            [sys.executable, str(script), "--robots", robot, "--out", str(tmp_path)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
        )
        for robot in ("panda", "ur5")
    }
    outputs = {robot: run.communicate(timeout=900) for robot, run in runs.items()}
    for robot, run in runs.items():
        assert run.returncode == 0, outputs[robot][1]
    panda_all, ur5_all = (
        next(line.split() for line in outputs[robot][0].splitlines() if line.startswith("all "))
        for robot in ("panda", "ur5")
    )
    assert panda_all[1:4] == ["700", "700", "700"]
    assert ur5_all[1:3] == ["700", "700"] and int(ur5_all[3]) >= 600  # hulls over the concave forearm: docs
