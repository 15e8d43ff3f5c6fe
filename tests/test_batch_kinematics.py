from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.batch_kinematics import KinematicChain

from .conftest import random_configurations


def test_placements_match_pinocchio(robot: ck.Robot, rng: np.random.Generator) -> None:
    configurations = random_configurations(robot, rng, 200)
    rotations, translations = KinematicChain.from_model(robot.model).placements(configurations)
    data = robot.model.createData()
    for k, q in enumerate(configurations):
        pin.forwardKinematics(robot.model, data, q)
        for j in range(1, robot.model.njoints):
            np.testing.assert_allclose(rotations[k, j - 1], data.oMi[j].rotation, atol=1e-14)
            np.testing.assert_allclose(translations[k, j - 1], data.oMi[j].translation, atol=1e-14)


def test_unaligned_axes_and_rotated_placements_match_pinocchio(rng: np.random.Generator) -> None:
    # a chain unlike the CPR's: tilted axes, rotated placements, a branch off the first joint
    model = pin.Model()
    parent = 0
    for k in range(4):
        placement = pin.SE3(pin.rpy.rpyToMatrix(*rng.uniform(-np.pi, np.pi, 3)), rng.normal(size=3))
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        joint = (
            pin.JointModelRevoluteUnaligned(axis) if k % 2 == 0 else pin.JointModelPrismaticUnaligned(axis)
        )
        parent = model.addJoint(0 if k == 3 else parent, joint, placement, f"j{k}")
    chain = KinematicChain.from_model(model)
    assert not chain.aligned.any() and chain.parents.tolist() == [-1, 0, 1, -1]
    configurations = rng.uniform(-2.0, 2.0, (50, model.nq))
    rotations, translations = chain.placements(configurations)
    data = model.createData()
    for k, q in enumerate(configurations):
        pin.forwardKinematics(model, data, q)
        for j in range(1, model.njoints):
            np.testing.assert_allclose(rotations[k, j - 1], data.oMi[j].rotation, atol=1e-13)
            np.testing.assert_allclose(translations[k, j - 1], data.oMi[j].translation, atol=1e-13)


def test_joint_with_more_than_one_coordinate_is_refused() -> None:
    model = pin.Model()
    model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "ball")
    with pytest.raises(ck.CprKinError, match="joint 'ball' has 4 coordinates"):
        KinematicChain.from_model(model)
