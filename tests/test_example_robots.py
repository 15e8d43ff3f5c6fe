"""Robots no one here wrote, end to end through the CLI: a scene with an obstacle plans, passes
``check`` and is drawn, for the SO-100, the SO-101, the UR5, the Panda and the xArm7 of example-robot-data
(the SO-100's wrist roll and gripper carry no collision mesh: a path must still move them).

Each scene is drawn at random (seeded) in the robot's own workspace: a start configuration, a
goal pose of the tool, and a sphere on the tool's straight joint-space way between them, so
that the plan must go around it. The goal is a pose, solved by the numerical IK.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.packages import example_robot
from planning.cli import main

ARMS = ("so100", "so101", "ur5", "panda", "xarm7")
MARGIN_M = 0.02


def blocked_scene(name: str, robot: ck.Robot, seed: int) -> dict[str, Any]:
    """A start, a goal pose and a sphere across the straight way between them, all clear of the margin."""
    rng = np.random.default_rng(seed)
    middle, half = (
        (robot.limits.lower + robot.limits.upper) / 2,
        (robot.limits.upper - robot.limits.lower) / 2,
    )
    reach = float(np.linalg.norm(ck.frame_poses(robot, middle[None])[0][:3, 3]))
    for _ in range(2000):
        start, goal = rng.uniform(middle - 0.6 * half, middle + 0.6 * half, (2, robot.nq))
        tools = ck.frame_poses(robot, np.array([start, (start + goal) / 2, goal]))
        if np.linalg.norm(tools[0, :3, 3] - tools[2, :3, 3]) < 0.5 * reach or tools[1, 2, 3] < 0.1 * reach:
            continue
        sphere = ck.Obstacle.sphere(0.12 * reach, tuple(tools[1, :3, 3]), name="ball")
        world = ck.CollisionWorld(robot, [sphere])
        clear = world.clearance_batch(np.array([start, goal])).clearance_m.min() > MARGIN_M + 0.02
        self_clear = world.self_collision.distances(np.array([start, goal]))[0].min() > 0.02
        if clear and self_clear:
            return {
                "name": f"{name}_ball",
                "robot": name,
                "safety_margin": MARGIN_M,
                "start": {"q": start.tolist()},
                "goal": {"pose": {"xyz": tools[2, :3, 3].tolist(), "rpy": rpy(tools[2, :3, :3])}},
                "obstacles": [
                    {
                        "name": "ball",
                        "shape": "sphere",
                        "radius": 0.12 * reach,
                        "xyz": [float(v) for v in sphere.xyz],
                    }
                ],
                "planner": {"seed": seed},
            }
    raise AssertionError(f"no scene drawn for {name}")


def rpy(rotation: np.ndarray) -> list[float]:
    import pinocchio as pin

    return [float(v) for v in pin.rpy.matrixToRpy(rotation)]


@pytest.mark.parametrize("name", ARMS)
def test_a_scene_with_an_obstacle_plans_passes_check_and_is_drawn(
    name: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    robot = ck.load_robot(example_robot(name))
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(blocked_scene(name, robot, seed=3)))
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
