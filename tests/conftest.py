"""Shared fixtures: the bundled CPR, the paper's scene, geometric paths to time, the example pick
and place planned once, a stop that says yes after a count of questions, a script loaded
as a module or run for its markdown table, a UR5 on a slow lift, and trimesh's shared random
draws seeded."""

from __future__ import annotations

import os

# numba's dispatchers, whatever kernels compiled ahead of time this checkout holds: tests read their
# signatures and compile kernels of their own (tests/test_ahead.py runs the kernels compiled ahead)
os.environ["CPR_KERNELS"] = "jit"

import importlib.util
import json
import subprocess
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh.util

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.curves.spline_settings import SplineSettings
from planning.curves.trajectory import Trajectory
from planning.io.scene_file import SceneFile, load_scene_file
from planning.task import TaskMotion, plan_task

PAPER_START_TCP = (0.5, 0.45, 0.25)
PAPER_GOAL_TCP = (-0.5, 0.45, 0.25)

REST = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
LIFT = np.array([0.4, 0.25, -0.1, 0.0, 0.0])
"""An offset of the middle waypoints: the path lifts over something, a curved path."""


@pytest.fixture(autouse=True)
def seeded_trimesh(monkeypatch: pytest.MonkeyPatch) -> None:
    """trimesh's unseeded draws seeded, for each test anew.

    trimesh draws from one generator it seeds from the OS wherever it is given no seed: its
    containment test, for one, casts a ray through an edge again in a random direction. An
    oracle built on it must give the same answer every run.
    """
    shared = np.random.default_rng(0)

    def generator(seed: object = None) -> np.random.Generator:
        return shared if seed is None else np.random.default_rng(seed)  # type: ignore[arg-type]

    monkeypatch.setattr(trimesh.util, "random_generator", generator)


SCRIPTS = Path(__file__).resolve().parents[1] / "scripts"


def load_script(name: str) -> ModuleType:
    """``scripts/<name>.py`` as a module, in ``sys.modules`` (where a dataclass looks its module up)."""
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def run_script(name: str, *arguments: str, timeout_s: float = 600) -> subprocess.CompletedProcess[str]:
    """``scripts/<name>.py`` run in a new process with ``arguments``: what it printed and its exit code."""
    return subprocess.run(
        [sys.executable, str(SCRIPTS / f"{name}.py"), *arguments],
        capture_output=True,
        text=True,
        timeout=timeout_s,
        check=False,
    )


def script_table(name: str, *arguments: str) -> list[list[str]]:
    """``scripts/<name>.py`` run in a new process with ``arguments``: its markdown table's rows.

    The header row first, each row's cells stripped; the script must exit 0 (else the end of
    its standard error is the failure's message).
    """
    completed = run_script(name, *arguments)
    assert completed.returncode == 0, completed.stderr[-2000:]
    lines = [line for line in completed.stdout.splitlines() if line.startswith("| ")]
    return [[cell.strip() for cell in line.split("|")[1:-1]] for line in lines]


def spline_path(nodes: np.ndarray) -> Trajectory:
    """The planner's geometric path: the rest-to-rest spline through nodes on uniform knots."""
    return (
        SepticSplineSolver(uniform_knots(len(nodes) - 1, float(len(nodes) - 1)), REST).solve(nodes).trajectory
    )


def limits_of(robot: ck.Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return robot.limits.velocity, robot.limits.acceleration, robot.limits.jerk


LIFT_SPEED_M_S = 0.02
"""The lift's velocity limit under :func:`ur5_on_a_lift` [m/s] (a PR2's torso: 0.013)."""


@pytest.fixture(scope="session")
def ur5_on_a_lift(tmp_path_factory: pytest.TempPathFactory) -> ck.Robot:
    """example-robot-data's UR5 on a prismatic lift of 0.4 m at :data:`LIFT_SPEED_M_S`, its first joint.

    The arm's joints move at 3.15-3.2 rad/s: a mobile manipulator's torso and arm (a PR2, a Fetch).
    """
    from cpr_kin.model.packages import example_robot

    lift = (
        '<link name="lift_link"/><joint name="lift_joint" type="prismatic"><parent link="world"/>'
        '<child link="lift_link"/><axis xyz="0 0 1"/>'
        f'<limit lower="0" upper="0.4" velocity="{LIFT_SPEED_M_S}" effort="1000"/></joint>'
    )
    text = example_robot("ur5").read_text()
    mount = '<joint name="world_joint" type="fixed">\n    <parent link="world"/>'
    if mount not in text:
        raise AssertionError("example-robot-data's UR5 no longer joins base_link to world as expected")
    text = text.replace(mount, lift + mount.replace('"world"', '"lift_link"'))
    path = tmp_path_factory.mktemp("lift") / "ur5_on_a_lift.urdf"
    path.write_text(text)
    return ck.load_robot(path, srdf=example_robot("ur5").parents[1] / "srdf" / "ur5.srdf")


@pytest.fixture(scope="session")
def robot() -> ck.Robot:
    return ck.load_cpr()


@pytest.fixture(scope="session")
def crate() -> ck.Obstacle:
    return ck.Obstacle.box(size=(0.3, 0.3, 0.3), xyz=(0.0, 0.6, 0.15), name="crate")


@pytest.fixture(scope="session")
def paper_world(robot: ck.Robot, crate: ck.Obstacle) -> ck.CollisionWorld:
    return ck.CollisionWorld(robot, [crate])


@dataclass(frozen=True)
class PlannedTask:
    """A scene file's task and its plan."""

    read: SceneFile
    task: TaskMotion


PICK = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "pick_and_place.yaml"


@pytest.fixture(scope="session")
def pick_and_place() -> PlannedTask:
    """The example pick and place (examples/scenes/pick_and_place.yaml), planned once a session."""
    read = load_scene_file(PICK)
    return PlannedTask(read, plan_task(read.scene, read.task))


def after_calls(count: int) -> tuple[list[int], Callable[[], bool]]:
    """A stop that says ``True`` from its ``count + 1``-th call on, and the list of its calls."""
    calls: list[int] = []

    def stop() -> bool:
        calls.append(1)
        return len(calls) > count

    return calls, stop


@pytest.fixture()
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def strict_loads(text: str) -> Any:
    """``text`` parsed as RFC 8259 JSON, which has no ``NaN``, ``Infinity`` or ``-Infinity``."""

    def refuse(constant: str) -> None:
        raise ValueError(f"{constant} is not JSON")

    return json.loads(text, parse_constant=refuse)


def random_configurations(robot: ck.Robot, rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(robot.limits.lower, robot.limits.upper, (n, robot.nq))


def damped_step(jacobian: np.ndarray, error: np.ndarray, damping: float) -> np.ndarray:
    """The damped least-squares step ``J^T (J J^T + lambda^2 I)^-1 e``, ``lambda = damping``, by NumPy.

    The reference the compiled descents (``cpr_kin.kinematics.tool_chain``) are held to.
    """
    system = jacobian @ jacobian.T + damping**2 * np.eye(len(error))
    return np.asarray(jacobian.T @ np.linalg.solve(system, error))


@pytest.fixture(scope="session")
def lines(robot: ck.Robot) -> list[tuple[np.ndarray, np.ndarray]]:
    """Start and goal pairs: the paper's, then 8 random ones in the moving joints."""
    rng = np.random.default_rng(11)
    pairs = [(ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP))]
    lower, upper = robot.limits.lower, robot.limits.upper
    for _ in range(8):
        a, b = rng.uniform(lower, upper), rng.uniform(lower, upper)
        a[3:] = b[3:] = 0.0
        pairs.append((a, b))
    return pairs


def turning_balls(
    balls: dict[str, tuple[bool, float, float]],
) -> tuple[pin.Model, pin.GeometryModel, dict[str, int]]:
    """A joint turning about z through a full turn, and balls centred on the x axis.

    ``balls``: ``name: (turning, radius [m], x [m])``, a turning ball carried by the joint;
    a turning ball's distance to a fixed ball at the origin never changes. Returns the model,
    the geometry model and each ball's geometry index.
    """
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "spin")
    model.lowerPositionLimit[:] = -np.pi
    model.upperPositionLimit[:] = np.pi
    geometry_model = pin.GeometryModel()
    ids = {}
    for name, (turning, radius, x) in balls.items():
        placement = pin.SE3(np.eye(3), np.array([x, 0.0, 0.0]))
        ball = pin.GeometryObject(name, joint if turning else 0, placement, coal.Sphere(radius))
        ids[name] = int(geometry_model.addGeometryObject(ball))
    return model, geometry_model, ids
