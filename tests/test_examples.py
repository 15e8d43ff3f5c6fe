"""The examples run as a user runs them: each script in a process of its own, the notebook in a kernel."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

pytestmark = pytest.mark.slow  # every test here starts a process or a kernel

EXPECTED = {
    "plan_a_scene.py": ["shelf: ", "certified clearance", "wrote out/examples/plan/trajectory.json"],
    "inspect_clearance.py": ["certified clearance 0.1", "the straight swing: accepted False"],
    "batch_a_folder.py": ["6/6 planned"],
    "bring_your_own_robot.py": ["tool 'panda_hand_tcp'", "goal met by forward kinematics: True"],
    "plan_through_a_point_cloud.py": [
        "blocks of voxels from 100000 points",
        "primitives: ",
        "point cloud: ",
        "wrote out/examples/cloud/trajectory.json",
    ],
    "pick_and_place.py": [
        "free    0.000 -> ",
        "attach ",
        "detach ",
        "verified True, certified clearance 0.",
        "against the task: kept",
    ],
    "tool_lines.py": ["approach: 0.", "certified deviation 0.", "straight down: ", "% achieved"],
    "check_a_trajectory.py": [
        "theirs.json: verified",
        "edited.json: FAILS: is not continuous (C3) at t = 1 s (knot 1): the position of joint 'd2' jumps",
    ],
}


def test_every_example_script_is_run() -> None:
    assert sorted(p.name for p in EXAMPLES.glob("*.py")) == sorted(EXPECTED)


@pytest.mark.parametrize("script", sorted(EXPECTED))
def test_an_example_script_runs_from_any_folder(script: str, tmp_path: Path) -> None:
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / script)], cwd=tmp_path, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    for line in EXPECTED[script]:
        assert line in done.stdout, done.stdout
    assert done.stderr == ""


def test_the_pick_and_place_example_sets_a_pandas_can_down_on_a_table(tmp_path: Path) -> None:
    scene = EXAMPLES / "scenes" / "panda_pick_and_place.yaml"
    done = subprocess.run(
        [sys.executable, str(EXAMPLES / "pick_and_place.py"), str(scene)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    kinds = [line.split()[0] for line in done.stdout.splitlines()[:9]]
    assert kinds == ["free", "line", "wait", "attach", "line", "free", "line", "detach", "line"]
    assert "verified True" in done.stdout and "against the task: kept" in done.stdout


@pytest.mark.parametrize("robot", ["so101", "ur5", "panda", "xarm7"])
def test_the_own_robot_example_runs_for_every_arm_and_passes_the_cli_check(
    robot: str, tmp_path: Path
) -> None:
    script = EXAMPLES / "bring_your_own_robot.py"
    done = subprocess.run([sys.executable, str(script), robot], cwd=tmp_path, capture_output=True, text=True)
    assert done.returncode == 0 and "goal met by forward kinematics: True" in done.stdout, done.stderr
    done = subprocess.run(
        [sys.executable, "-m", "planning.cli", "check", f"{robot}_turn.yaml", f"{robot}_turn.json"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0 and f"{robot}_turn.json: verified against" in done.stdout, done.stderr


def test_the_example_scene_names_its_robot_relative_to_itself(tmp_path: Path) -> None:
    from planning import load_scene

    scene = load_scene(EXAMPLES / "scenes" / "shelf.yaml")
    assert scene.robot is not None and scene.robot.urdf.is_file() and scene.robot.urdf.name == "cpr.urdf"


def test_the_notebook_plans_and_shows_the_viewer_inline(tmp_path: Path) -> None:
    import nbclient
    import nbformat

    notebook = nbformat.read(EXAMPLES / "plan_and_show.ipynb", as_version=4)  # type: ignore[no-untyped-call]
    nbclient.NotebookClient(
        notebook, timeout=300, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    ).execute()
    outputs = [output for cell in notebook.cells if cell.cell_type == "code" for output in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    printed = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "certified clearance 0.1" in printed and "closest: ('tool', 'crate')" in printed
    assert "point cloud: " in printed and "blocks of voxels" in printed  # planned through the cloud too
    assert "line   0.00 -> " in printed and "wait " in printed and "verified True" in printed  # the task
    shown = outputs[-1]["data"]["text/html"]
    assert shown.startswith("<div") and "<iframe srcdoc=" in shown and "meshcat" in shown
