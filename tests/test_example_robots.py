"""Robots no one here wrote, end to end through the CLI: a scene with an obstacle plans, passes
``check`` and is drawn, for the SO-100, the SO-101, the UR5, the Panda and the xArm7 of example-robot-data
(the SO-100's wrist roll and gripper carry no collision mesh: a path must still move them).

Each scene is drawn at random (seeded) in the robot's own workspace
(:func:`planning.bench.arm_scenes.blocked_scene`): a start configuration, a goal pose of the
tool, and a sphere on the tool's straight joint-space way between them, so that the plan must
go around it. The goal is a pose, solved by the numerical IK.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest
import yaml

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.bench.arm_scenes import blocked_scene
from planning.cli import main

ARMS = ("so100", "so101", "ur5", "panda", "xarm7")
MARGIN_M = 0.02


@pytest.mark.parametrize("name", ARMS)
def test_a_scene_with_an_obstacle_plans_passes_check_and_is_drawn(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = ck.load_robot(example_robot(name))
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(blocked_scene(f"{name}_ball", name, robot, seed=3, margin_m=MARGIN_M)))
    out = tmp_path / "out"
    assert main(["plan", str(scene), "--out", str(out)]) == 0, capsys.readouterr().err
    trajectory = out / "trajectory.json"
    document = json.loads(trajectory.read_text())
    assert document["joint_names"] == list(robot.joint_names)
    assert document["scene"]["robot"]["urdf"] == str(example_robot(name))  # the file records its robot
    capsys.readouterr()
    assert main(["check", str(scene), str(trajectory)]) == 0, capsys.readouterr().out
    assert "verified against" in capsys.readouterr().out
    assert main(["show", str(trajectory), "--html", str(tmp_path / "show.html")]) == 0
    assert "<script" in (tmp_path / "show.html").read_text()
