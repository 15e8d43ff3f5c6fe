"""A payload in the scene: torque-limited plans, the torque check, refusals, the file and the report."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from planning import PayloadTooHeavyError, build_problem, plan, torque_profile
from planning.cli import main
from planning.io.report import report_markdown
from planning.io.scene_file import parse_scene, scene_document
from planning.pipeline.result import PlanResult
from planning.utilisation import TORQUE, limit_usage

SCENE: dict[str, Any] = {
    "name": "lift",
    "start": {"q": [0.0, 0.1, 0.1, 0.0, 0.0]},
    "goal": {"q": [1.5, 0.5, 0.4, 1.0, 0.5]},
    "payload": {"mass_kg": 15.0, "com_in_tcp": [0.0, 0.0, 0.05]},
}


def scene_with(**changes: Any) -> dict[str, Any]:
    return {**SCENE, **changes}


@pytest.fixture(scope="module")
def loaded() -> PlanResult:
    return plan(parse_scene(SCENE))


@pytest.fixture(scope="module")
def bare() -> PlanResult:
    return plan(parse_scene(scene_with(payload=None)))


def test_a_heavy_payload_slows_the_motion_to_its_torque_limit(loaded: PlanResult, bare: PlanResult) -> None:
    profile = torque_profile(loaded.problem.dynamics, loaded.trajectory)
    assert profile.peak_utilisation.max() <= 1.0
    assert profile.peak_utilisation.max() >= 0.99  # it binds: no time left on the table
    assert loaded.metrics.torque_utilisation["d2"] == pytest.approx(profile.peak_utilisation[1])
    assert loaded.trajectory.duration > bare.trajectory.duration
    assert max(bare.metrics.torque_utilisation.values()) < 0.5


def test_the_report_and_the_usage_show_the_torques(loaded: PlanResult) -> None:
    usage = limit_usage(loaded.trajectory, loaded.robot.limits, dynamics=loaded.problem.dynamics)
    assert usage.orders[-1] == TORQUE and usage.usage.shape[1] == 4
    report = report_markdown(loaded)
    assert "a 15 kg payload at [0.0, 0.0, 0.05] m in 'tcp'" in report and "d2 1.00" in report


def test_check_fails_a_trajectory_too_fast_for_the_payload(
    bare: PlanResult, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from planning.io.trajectory_io import write_trajectory

    write_trajectory(bare, tmp_path / "fast.json")
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(SCENE))
    code = main(["check", str(scene), str(tmp_path / "fast.json")])
    out = capsys.readouterr().out
    assert code == 3 and re.search(
        r"drives the torque of joint 'd2' to 1\.\d+ x its effort limit \(2\d\d(\.\d)? of 200 N\)", out
    )
    (tmp_path / "bare.yaml").write_text(yaml.safe_dump(scene_with(payload=None)))
    assert main(["check", str(tmp_path / "bare.yaml"), str(tmp_path / "fast.json")]) == 0
    assert "torques within effort limits" in capsys.readouterr().out


def test_a_payload_the_motors_cannot_hold_is_exit_3(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(scene_with(payload={"mass_kg": 20.0})))
    code = main(["plan", str(scene), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 3 and not (tmp_path / "out").exists()
    assert "holding the start still with the 20 kg payload takes 237.4 N at joint 'd2'" in err
    assert "beyond its effort limit 200 N" in err and "Traceback" not in err
    assert "lighten the payload or choose another start" in err
    with pytest.raises(
        PayloadTooHeavyError, match="choose another start, or give the URDF the effort"
    ) as raised:
        build_problem(parse_scene(scene_with(payload=None, torque_scale=0.005)))
    assert "payload" not in str(raised.value)  # none was given: the arm alone is too heavy


@pytest.mark.parametrize(
    ("payload", "message"),
    [
        ({"mass_kg": -1}, "payload.mass_kg = -1"),
        ({"mass_kg": "heavy"}, "payload.mass_kg = 'heavy'"),
        ({"mass": 1}, "payload.mass: unknown key"),
        ({"mass_kg": 1, "com_in_tcp": [0, 0]}, "payload.com_in_tcp"),
        ({"mass_kg": 1, "inertia": [0.1, 0.1, 0.5]}, "payload: payload inertia"),
        ({"mass_kg": 1, "frame": "gripper"}, "unknown frame 'gripper'"),
    ],
)
def test_a_bad_payload_is_exit_2_naming_it(
    payload: dict[str, Any], message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(scene_with(payload=payload)))
    code = main(["plan", str(scene), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and message in err and err.count("\n") == 1, err


def test_torque_scale_is_checked_and_the_payload_round_trips() -> None:
    with pytest.raises(Exception, match="torque_scale = 2"):
        parse_scene(scene_with(torque_scale=2.0))
    payload = {"mass_kg": 2.0, "com_in_tcp": [0.0, 0.01, 0.1], "inertia": [0.01, 0.02, 0.02], "frame": "tcp"}
    scene = parse_scene(scene_with(payload=payload, torque_scale=0.8))
    again = parse_scene(scene_document(scene))
    assert again.payload == scene.payload and again.torque_scale == 0.8
    assert isinstance(scene.payload, ck.Payload)
    assert np.allclose(np.array(scene.payload.inertia_kg_m2), np.diag([0.01, 0.02, 0.02]))


def test_torques_that_never_bind_leave_the_plan_byte_for_byte_as_without_them(bare: PlanResult) -> None:
    model = bare.robot.model.copy()
    model.effortLimit[:] = 0.0  # no known effort: no torque rows, no torque scale, no check
    unlimited = dataclasses.replace(bare.robot, model=model)
    light = parse_scene(scene_with(payload={"mass_kg": 0.5, "com_in_tcp": [0.0, 0.0, 0.02]}))
    without = plan(parse_scene(scene_with(payload=None)), unlimited)
    assert not without.problem.dynamics.limited and bare.problem.dynamics.limited
    for other in (without, plan(light)):
        assert other.verification.accepted
        np.testing.assert_array_equal(other.trajectory.knots, bare.trajectory.knots)
        np.testing.assert_array_equal(other.trajectory.coefficients, bare.trajectory.coefficients)
