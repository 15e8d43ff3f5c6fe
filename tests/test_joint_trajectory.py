"""The ROS JointTrajectory export: the message's shape, its samples against the trajectory, the CLI."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml

from planning.cli import main
from planning.errors import PlanningError
from planning.io import joint_trajectory as joint_trajectory_module
from planning.io.joint_trajectory import joint_trajectory, write_joint_trajectory
from tests.conftest import LIFT, spline_path

JOINTS = ("theta1", "d2", "d3", "theta4", "theta5")
POINT_FIELDS = [
    "positions",
    "velocities",
    "accelerations",
    "effort",
    "time_from_start",
]  # JointTrajectoryPoint


def seconds(point: dict[str, object]) -> float:
    stamp = point["time_from_start"]
    assert isinstance(stamp, dict) and set(stamp) == {"sec", "nanosec"} and 0 <= stamp["nanosec"] < 10**9
    return float(stamp["sec"] + stamp["nanosec"] * 1e-9)


@pytest.fixture(scope="module")
def path_nodes() -> np.ndarray:
    start = np.array([0.7, 0.15, 0.37, 0.0, 0.0])
    return np.array(
        [start, start + LIFT, -start[[0]] * [1, 0, 0, 0, 0] + start * [0, 1, 1, 1, 1], start * 0.5]
    )


def test_the_points_sample_the_trajectory_at_the_rate_and_at_its_end(path_nodes: np.ndarray) -> None:
    trajectory = spline_path(path_nodes)  # 3 s
    document = joint_trajectory(trajectory, JOINTS, rate_hz=7.0)
    assert list(document) == ["header", "joint_names", "points"] and document["joint_names"] == list(JOINTS)
    points = document["points"]
    assert all(list(p) == POINT_FIELDS for p in points)
    times = np.array([seconds(p) for p in points])
    assert len(points) == 22 and times[-1] == pytest.approx(3.0, abs=1e-9)  # 0, 1/7, ..., 20/7, then 3 s
    np.testing.assert_allclose(np.diff(times[:-1]), 1 / 7, atol=1e-9)
    np.testing.assert_allclose([p["positions"] for p in points], trajectory(times), atol=1e-12)
    np.testing.assert_allclose(points[0]["positions"], path_nodes[0], atol=1e-12)
    np.testing.assert_allclose(points[-1]["positions"], path_nodes[-1], atol=1e-12)


def test_velocities_and_accelerations_are_the_derivatives_of_the_positions(path_nodes: np.ndarray) -> None:
    points = joint_trajectory(spline_path(path_nodes), JOINTS, rate_hz=2000.0)["points"]
    q, v, a = (
        np.array([p[key] for p in points[:-1]]) for key in ("positions", "velocities", "accelerations")
    )
    h = 1 / 2000.0
    np.testing.assert_allclose((q[2:] - q[:-2]) / (2 * h), v[1:-1], atol=1e-5)  # central differences
    np.testing.assert_allclose((v[2:] - v[:-2]) / (2 * h), a[1:-1], atol=1e-4)


@pytest.mark.parametrize("rate", [0.0, -5.0, float("nan"), 1e6])
def test_a_bad_rate_is_refused(path_nodes: np.ndarray, rate: float) -> None:
    with pytest.raises(PlanningError, match=r"rate = .* Hz must be a number in \[1, 10000\] Hz"):
        joint_trajectory(spline_path(path_nodes), JOINTS, rate)


@pytest.mark.parametrize("chunk", [3, 10_000])
def test_streamed_yaml_and_json_files_read_back_as_the_document(
    path_nodes: np.ndarray, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, chunk: int
) -> None:
    monkeypatch.setattr(joint_trajectory_module, "CHUNK_POINTS", chunk)  # written in parts of any size
    trajectory = spline_path(path_nodes)
    document = joint_trajectory(trajectory, JOINTS, 50.0)
    for name in ("t.yaml", "t.json"):
        write_joint_trajectory(trajectory, JOINTS, tmp_path / name, 50.0)
    assert yaml.safe_load((tmp_path / "t.yaml").read_text()) == document  # PyYAML's reading
    assert json.loads((tmp_path / "t.json").read_text()) == document
    with pytest.raises(PlanningError, match=r"must end in one of \['.yaml', '.yml', '.json'\]"):
        write_joint_trajectory(trajectory, JOINTS, tmp_path / "t.csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["t.json", "t.yaml"]  # nothing half-written


@pytest.mark.parametrize(
    "value", [1e-05, -2.5e-300, 1e20, 0.1, -0.0, 123456789.0, 5e-324, 1.7976931348623157e308]
)
def test_a_float_written_as_yaml_reads_back_as_itself(value: float) -> None:
    # PyYAML (YAML 1.1) reads 1e-05 as a string: an exponent needs a dot
    assert yaml.safe_load(joint_trajectory_module._yaml_float(value)) == value


def test_the_cli_exports_a_planned_trajectory(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from planning import paper_scene, plan, write_trajectory

    result = plan(paper_scene(seed=0))
    write_trajectory(result, tmp_path / "trajectory.json")
    out = tmp_path / "ros" / "trajectory.yaml"
    code = main(
        ["export", str(tmp_path / "trajectory.json"), "--format", "joint-trajectory", "--out", str(out)]
    )
    assert code == 0 and f"wrote {out}" in capsys.readouterr().out
    document = yaml.safe_load(out.read_text())
    assert seconds(document["points"][-1]) == pytest.approx(result.trajectory.duration, abs=1e-9)
    np.testing.assert_allclose(document["points"][-1]["positions"], result.waypoints[-1], atol=1e-9)
    code = main(
        [
            "export",
            str(tmp_path / "trajectory.json"),
            "--format",
            "joint-trajectory",
            "--rate",
            "0",
            "--out",
            str(out),
        ]
    )
    assert code == 2 and "rate = 0.0 Hz must be a number in [1, 10000] Hz" in capsys.readouterr().err


@pytest.mark.slow
def test_a_million_points_are_streamed_in_bounded_memory(tmp_path: Path) -> None:
    """99.99 s at 10 kHz, just under the cap: the export's peak memory stays that of a small one.

    Before streaming, 25 s at 10 kHz took 3.4 GB and 99.99 s ran out of memory (exit 4).
    """
    import subprocess
    import sys

    measured = (  # the export's own peak resident memory [KiB], printed by the child at its end
        "import resource, sys; from planning.cli import main; code = main(sys.argv[1:]); "
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss, file=sys.stderr); raise SystemExit(code)"
    )

    def export(duration_s: float, name: str) -> int:
        document = {
            "format": "cpr-trajectory/1",
            "joint_names": list(JOINTS),
            "robot": "cpr",
            "scene": {},
            "waypoints": [],
            "knots": [0.0, duration_s],
            "segments": [
                {"t0": 0.0, "t1": duration_s, "coeffs": [[0.1 * j, 0.01, 0, 0, 0, 0, 0, 0] for j in range(5)]}
            ],
        }
        (tmp_path / f"{name}.json").write_text(json.dumps(document))
        out = tmp_path / f"{name}.yaml"
        arguments = [
            "export",
            str(tmp_path / f"{name}.json"),
            "--format",
            "joint-trajectory",
            "--rate",
            "10000",
        ]
        run = subprocess.run(
            [sys.executable, "-c", measured, *arguments, "--out", str(out)],
            check=True,
            capture_output=True,
            text=True,
        )
        peak_kib = int(run.stderr.split()[-1])
        assert yaml.safe_load(out.read_text().split("points:")[0])["joint_names"] == list(JOINTS)
        return peak_kib

    small = export(0.1, "small")  # 1,001 points
    large = export(99.99, "large")  # 999,901 points, 340 MB of YAML
    assert (tmp_path / "large.yaml").read_text().count("- positions:") == 999_901
    print(f"export peak memory: {small} KiB (1,001 points), {large} KiB (999,901 points)")
    assert large < small + 200 * 1024, f"peak {large} KiB against {small} KiB for a thousand points"
