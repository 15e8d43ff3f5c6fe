"""The robot's torques with a payload: RNEA checked against ABA, the Jacobian and analytic gravity."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.kinematics.dynamics import MAX_PAYLOAD_KG

GRAVITY = 9.81


@pytest.fixture(scope="module")
def robot() -> ck.Robot:
    return ck.load_cpr()


def random_states(robot: ck.Robot, count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    limits = robot.limits
    q = rng.uniform(limits.lower, limits.upper, (count, robot.nq))
    return q, rng.normal(size=(count, robot.nq)), rng.normal(size=(count, robot.nq))


def test_the_carried_mass_holds_the_vertical_axis_up(robot: ck.Robot) -> None:
    # d2 lifts every link above it and the payload: its force is their weight, whatever the pose
    above = sum(
        robot.model.inertias[i].mass for i in range(robot.model.getJointId("d2"), robot.model.njoints)
    )
    q, _, _ = random_states(robot, 5, 0)
    for mass in (0.0, 2.0, 5.0):
        dynamics = ck.robot_dynamics(robot, ck.Payload(mass, (0.01, -0.02, 0.05)))
        d2 = robot.limits.index("d2")
        assert dynamics.torques(q)[:, d2] == pytest.approx(np.full(5, (above + mass) * GRAVITY), rel=1e-4)


def test_a_point_payload_adds_the_tool_jacobian_times_its_weight(robot: ck.Robot) -> None:
    bare = ck.robot_dynamics(robot)
    loaded = ck.robot_dynamics(robot, ck.Payload(3.0))
    q, _, _ = random_states(robot, 6, 1)
    frame = robot.frame_id(robot.tcp_frame)
    for row in q:
        jacobian = pin.computeFrameJacobian(robot.model, robot.data, row, frame, pin.LOCAL_WORLD_ALIGNED)[:3]
        expected = jacobian.T @ np.array([0.0, 0.0, 3.0 * GRAVITY])
        assert loaded.torques(row)[0] - bare.torques(row)[0] == pytest.approx(expected, abs=1e-3)


def test_rnea_and_aba_are_inverse_with_a_payload(robot: ck.Robot) -> None:
    inertia = ((0.02, 0.0, 0.001), (0.0, 0.03, 0.0), (0.001, 0.0, 0.04))
    dynamics = ck.robot_dynamics(robot, ck.Payload(2.5, (0.0, 0.05, 0.1), inertia))
    data = dynamics.model.createData()
    q, qd, qdd = random_states(robot, 10, 2)
    torques = dynamics.torques(q, qd, qdd)
    for k in range(10):
        assert pin.aba(dynamics.model, data, q[k], qd[k], torques[k]) == pytest.approx(qdd[k], abs=1e-8)


def test_the_path_terms_add_up_to_the_torques(robot: ck.Robot) -> None:
    dynamics = ck.robot_dynamics(robot, ck.Payload(4.0, (0.0, 0.0, 0.08)))
    q, dq, ddq = random_states(robot, 8, 3)
    slope, curve, offset = dynamics.path_terms(q, dq, ddq)
    rng = np.random.default_rng(4)
    speed, push = rng.uniform(0.1, 2.0, (8, 1)), rng.normal(size=(8, 1))
    expected = dynamics.torques(q, dq * speed, dq * push + ddq * speed**2)
    assert slope * push + curve * speed**2 + offset == pytest.approx(expected, abs=1e-9)


def test_inertia_is_a_rigid_bodys(robot: ck.Robot) -> None:
    assert ck.Payload(1.0, inertia_kg_m2=(0.1, 0.2, 0.25)).inertia_kg_m2 == (  # type: ignore[arg-type]
        (0.1, 0.0, 0.0),
        (0.0, 0.2, 0.0),
        (0.0, 0.0, 0.25),
    )
    with pytest.raises(ck.CprKinError, match="is not a rigid body's"):
        ck.Payload(1.0, inertia_kg_m2=(0.1, 0.1, 0.5))  # type: ignore[arg-type]
    with pytest.raises(ck.CprKinError, match="is not a rigid body's"):
        ck.Payload(1.0, inertia_kg_m2=((0.1, 0.05, 0), (0.0, 0.1, 0), (0, 0, 0.1)))


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"mass_kg": -1.0}, r"payload mass_kg = -1.0 is outside \[0, 1000\] kg"),
        ({"mass_kg": float("nan")}, "mass_kg = nan is outside"),
        ({"mass_kg": MAX_PAYLOAD_KG * 2}, "is outside"),
        ({"mass_kg": 1.0, "com_in_frame_m": (0.0, 9.0, 0.0)}, "within 5 m of its frame"),
        ({"mass_kg": 1.0, "inertia_kg_m2": ((1.0, 2.0),)}, r"must be \[Ixx, Iyy, Izz\] or a 3 x 3 matrix"),
    ],
)
def test_a_bad_payload_is_refused_naming_the_value(arguments: dict[str, Any], message: str) -> None:
    with pytest.raises(ck.CprKinError, match=message):
        ck.Payload(**arguments)


def test_a_payload_frame_and_torque_scale_are_checked(robot: ck.Robot) -> None:
    with pytest.raises(ck.CprKinError, match="unknown frame 'gripper'"):
        ck.robot_dynamics(robot, ck.Payload(1.0, frame="gripper"))
    with pytest.raises(ck.CprKinError, match=r"torque_scale = 1.5 is outside \[0.001, 1\]"):
        ck.robot_dynamics(robot, torque_scale=1.5)
    scaled = ck.robot_dynamics(robot, torque_scale=0.5)
    assert scaled.effort == pytest.approx(0.5 * np.asarray(robot.limits.effort))


def test_unknown_efforts_do_not_limit_and_massless_links_are_named(tmp_path: Path) -> None:
    text = ck.cpr_urdf_path().read_text().replace('effort="20"', 'effort="0"')  # the wrist's: unknown
    start = text.index("<inertial>", text.index('<link name="wrist_link"'))
    stop = text.index("</inertial>", start) + len("</inertial>")
    urdf = tmp_path / "cpr.urdf"
    urdf.write_text(text[:start] + text[stop:])
    dynamics = ck.robot_dynamics(ck.load_cpr(urdf, ck.cpr_limits_path()))
    assert dynamics.limited and np.isfinite(dynamics.effort).tolist() == [True, True, True, False, False]
    assert dynamics.massless_links == ("wrist_link",)


@pytest.mark.parametrize(
    ("q", "qd"),
    [(np.zeros((2, 3)), None), (np.zeros((2, 5)), np.zeros((1, 5))), (np.zeros((2, 5)), np.zeros((2, 4)))],
)
def test_states_of_the_wrong_shape_are_refused_naming_it(
    robot: ck.Robot, q: np.ndarray, qd: np.ndarray | None
) -> None:
    dynamics = ck.robot_dynamics(robot)
    with pytest.raises(ck.CprKinError, match=r"one shape \(T, 5\)"):
        dynamics.torques(q, qd)
    with pytest.raises(ck.CprKinError, match=r"one shape \(T, 5\)"):
        dynamics.path_terms(q, np.zeros_like(q) if qd is None else qd, np.zeros_like(q))
