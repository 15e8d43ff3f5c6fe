from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from planning.errors import PlanningError
from planning.io.bundled import paper_scene
from planning.io.trajectory_io import write_samples, write_trajectory
from planning.io.trajectory_reader import read_trajectory
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult


@pytest.fixture(scope="module")
def result(robot: ck.Robot) -> PlanResult:
    return plan(paper_scene(0), robot)


def test_document_follows_the_design(result: PlanResult, tmp_path: Path) -> None:
    path = tmp_path / "trajectory.json"
    write_trajectory(result, path)
    document = json.loads(path.read_text())
    assert document["format"] == "cpr-trajectory/1"
    assert document["joint_names"] == ["theta1", "d2", "d3", "theta4", "theta5"]
    assert set(document) >= {
        "format",
        "joint_names",
        "robot",
        "srdf",
        "scene",
        "waypoints",
        "knots",
        "segments",
        "metrics",
    }
    assert document["srdf"].endswith("cpr.srdf")  # the SRDF whose pairs the checks left out
    assert set(document["scene"]) >= {"obstacles", "safety_margin", "start", "goal"}
    assert document["scene"]["obstacles"][0] == {
        "name": "crate",
        "shape": "box",
        "size": [0.3, 0.3, 0.3],
        "xyz": [0.0, 0.6, 0.15],
        "rpy": [0.0, 0.0, 0.0],
    }
    metrics = document["metrics"]
    for key in (
        "duration",
        "min_clearance",
        "max_node_deviation",
        "jerk_min",
        "jerk_max",
        "fitness",
        "planning_time_s",
        "evaluations",
    ):
        assert key in metrics
    # coeffs[j][k] is a_k of joint j: q_j(t) = sum_k a_k (t - t0)^k, evaluated by hand
    for segment in document["segments"]:
        t = 0.5 * (segment["t0"] + segment["t1"])
        by_hand = [sum(a * (t - segment["t0"]) ** k for k, a in enumerate(row)) for row in segment["coeffs"]]
        np.testing.assert_allclose(by_hand, result.trajectory(t), atol=1e-12)
    assert len(document["segments"]) == len(document["knots"]) - 1 == 4


def test_round_trip(result: PlanResult, tmp_path: Path) -> None:
    path = tmp_path / "trajectory.json"
    write_trajectory(result, path)
    back = read_trajectory(path)
    np.testing.assert_array_equal(back.trajectory.coefficients, result.trajectory.coefficients)
    np.testing.assert_array_equal(back.waypoints, result.waypoints)
    assert back.joint_names == result.joint_names
    assert back.metrics["min_clearance"] == result.metrics.min_clearance_m


def test_samples_csv(result: PlanResult, tmp_path: Path) -> None:
    path = tmp_path / "samples.csv"
    write_samples(result, path)
    lines = path.read_text().splitlines()
    header = lines[0].split(",")
    assert header[:6] == ["t", "theta1", "d2", "d3", "theta4", "theta5"]
    assert header[20] == "theta5_jerk" and len(header) == 24
    assert header[21:] == ["velocity_usage", "acceleration_usage", "jerk_usage"]
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    assert len(data) == int(np.ceil(4.0 / 0.012)) + 1
    np.testing.assert_allclose(np.diff(data[:-1, 0]), 0.012, atol=1e-6)
    np.testing.assert_allclose(data[:, 1:6], result.trajectory(data[:, 0]), atol=1e-9)
    np.testing.assert_allclose(data[:, 16:21], result.trajectory(data[:, 0], 3), atol=1e-9)
    limits = result.problem.robot.limits
    for r, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1):
        columns = data[:, 1 + 5 * r : 6 + 5 * r]  # the derivative's columns, by joint
        np.testing.assert_allclose(data[:, 20 + r], np.max(np.abs(columns) / limit, axis=1), rtol=1e-9)
    # the usage never exceeds what the exact extrema allow
    assert np.all(data[:, 21:] <= np.array(list(result.metrics.limit_utilisation.values())) + 1e-9)


@pytest.mark.parametrize("write", [write_trajectory, write_samples])
def test_what_is_no_plan_is_refused_naming_it_and_nothing_is_written(
    write: Callable[[object, Path], None], tmp_path: Path
) -> None:
    with pytest.raises(
        PlanningError, match=r"result is a NoneType; give a planning.PlanResult \(plan\(scene\)\)"
    ):
        write(None, tmp_path / "plan.json")
    assert list(tmp_path.iterdir()) == []
