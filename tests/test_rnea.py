"""The compiled RNEA against Pinocchio's: torques, armature, channels, the mass matrix it implies."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.batch_kinematics import KinematicChain
from cpr_kin.kinematics.rnea import BodyArrays, channel_torques
from cpr_kin.model.packages import example_robot

ROBOTS = ("cpr", "panda", "ur5", "tree")
"""Prismatic joints (the CPR), 7 and 6 revolute ones, and a tree (:data:`TREE`)."""
LINK = """<link name="{name}"><inertial><origin xyz="0.02 -0.03 0.1" rpy="0.3 -0.2 0.5"/>
<mass value="{mass}"/><inertia ixx="0.02" ixy="0.001" ixz="-0.002" iyy="0.03" iyz="0.003" izz="0.025"/>
</inertial></link>"""
JOINT = """<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>
<origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="{axis}"/>
<limit lower="-2" upper="2" effort="10" velocity="1"/></joint>"""
TREE = (
    '<robot name="tree"><link name="base"/>'
    + "".join(
        LINK.format(name=name, mass=mass)
        for name, mass in (("torso", 5), ("l1", 2), ("l2", 1), ("r1", 2), ("r2", 1))
    )
    + JOINT.format(
        name="lift", kind="prismatic", parent="base", child="torso", xyz="0 0 0.3", rpy="0 0 0", axis="0 0 1"
    )
    + JOINT.format(
        name="l1", kind="revolute", parent="torso", child="l1", xyz="0 0.2 0.5", rpy="0.4 0 0", axis="0 1 0"
    )
    + JOINT.format(
        name="l2", kind="revolute", parent="l1", child="l2", xyz="0.3 0 0", rpy="0 0.2 0.1", axis="0.6 0 0.8"
    )
    + JOINT.format(
        name="r1", kind="revolute", parent="torso", child="r1", xyz="0 -0.2 0.5", rpy="-0.4 0 0", axis="1 0 0"
    )
    + JOINT.format(
        name="r2", kind="prismatic", parent="r1", child="r2", xyz="0.3 0 0", rpy="0 0 0.3", axis="0 0.6 0.8"
    )
    + "</robot>"
)
"""A torso lifted by a prismatic joint, two arms on it (joints' frames turned, axes oblique)."""


@pytest.fixture(scope="module", params=ROBOTS)
def model(request: pytest.FixtureRequest) -> pin.Model:
    if request.param == "tree":
        model = pin.buildModelFromXML(TREE)
    else:
        robot = ck.load_cpr() if request.param == "cpr" else ck.load_robot(example_robot(request.param))
        # a payload at the tool, so that its body's centre and inertia are not the URDF's alone
        inertia = ((0.01, 0, 0), (0, 0.02, 0), (0, 0, 0.03))
        model = ck.robot_dynamics(robot, ck.Payload(2.0, (0.01, 0.02, 0.05), inertia)).model.copy()
    # a rotor's inertia on every joint, so that no term is zero
    model.armature = np.linspace(0.1, 0.5, model.nv)
    return model


def states(model: pin.Model, count: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    low = np.maximum(model.lowerPositionLimit, -np.pi)
    high = np.minimum(model.upperPositionLimit, np.pi)
    return (
        rng.uniform(low, high, (count, model.nq)),
        rng.normal(size=(count, model.nv)),
        rng.normal(size=(count, model.nv)),
    )


def compiled(
    model: pin.Model, q: np.ndarray, velocities: np.ndarray, accelerations: np.ndarray, gravities: np.ndarray
) -> np.ndarray:
    out = np.empty(velocities.shape)
    chain, bodies = KinematicChain.from_model(model).arrays, BodyArrays.from_model(model).arrays
    channel_torques(q, velocities, accelerations, gravities, chain, bodies, out)
    return out


def test_the_torques_are_pinocchios(model: pin.Model) -> None:
    q, qd, qdd = states(model, 40, 0)
    gravity = np.array(model.gravity.linear)
    torques = compiled(model, q, qd[None], qdd[None], gravity[None])[0]
    data = model.createData()
    expected = np.array([pin.rnea(model, data, *state) for state in zip(q, qd, qdd, strict=True)])
    assert torques == pytest.approx(expected, abs=1e-10 * max(1.0, np.abs(expected).max()))


def test_channels_share_the_placements_and_each_has_its_gravity(model: pin.Model) -> None:
    q, qd, qdd = states(model, 12, 1)
    gravity = np.array(model.gravity.linear)
    moon = gravity / 6.0
    torques = compiled(
        model,
        q,
        np.stack([qd, np.zeros_like(qd), qd]),
        np.stack([qdd, qdd, np.zeros_like(qdd)]),
        np.stack([gravity, np.zeros(3), moon]),
    )
    data = model.createData()
    model_moon = model.copy()
    model_moon.gravity.linear = moon
    for k in range(len(q)):
        assert torques[0, k] == pytest.approx(pin.rnea(model, data, q[k], qd[k], qdd[k]), abs=1e-9)
        # no gravity, no velocity: the mass matrix (armature included) times the acceleration
        assert torques[1, k] == pytest.approx(
            pin.crba(model, data, q[k], pin.Convention.WORLD) @ qdd[k], abs=1e-9
        )
        moving = pin.rnea(model_moon, model_moon.createData(), q[k], qd[k], np.zeros(model.nv))
        assert torques[2, k] == pytest.approx(moving, abs=1e-9)


def test_the_mass_matrix_it_implies_is_symmetric_and_positive(model: pin.Model) -> None:
    # column i of M(q): the torques of a unit acceleration of joint i, without gravity or velocity
    q, _, _ = states(model, 3, 2)
    n = model.nv
    for row in q:
        columns = compiled(
            model, np.tile(row, (n, 1)), np.zeros((1, n, n)), np.eye(n)[None], np.zeros((1, 3))
        )[0].T
        assert columns == pytest.approx(columns.T, abs=1e-12 * np.abs(columns).max())
        assert np.linalg.eigvalsh(columns).min() > 0.0


def test_the_path_terms_are_the_mass_matrix_coriolis_and_gravity(model: pin.Model) -> None:
    robot_like = ck.Dynamics(tuple(model.names[1:]), model, np.full(model.nv, np.inf))
    q, dq, ddq = states(model, 10, 3)
    slope, curve, offset = robot_like.path_terms(q, dq, ddq)
    data = model.createData()
    for k in range(len(q)):
        mass = pin.crba(model, data, q[k], pin.Convention.WORLD)
        assert slope[k] == pytest.approx(mass @ dq[k], abs=1e-9)
        coriolis = pin.computeCoriolisMatrix(model, data, q[k], dq[k])
        assert curve[k] == pytest.approx(mass @ ddq[k] + coriolis @ dq[k], abs=1e-9)
        assert offset[k] == pytest.approx(pin.computeGeneralizedGravity(model, data, q[k]), abs=1e-9)
