"""Shared fixtures: the bundled CPR and the paper's scene."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck

PAPER_START_TCP = (0.5, 0.45, 0.25)
PAPER_GOAL_TCP = (-0.5, 0.45, 0.25)


@pytest.fixture(scope="session")
def robot() -> ck.Robot:
    return ck.load_cpr()


@pytest.fixture(scope="session")
def crate() -> ck.Obstacle:
    return ck.Obstacle.box(size=(0.3, 0.3, 0.3), xyz=(0.0, 0.6, 0.15), name="crate")


@pytest.fixture(scope="session")
def paper_world(robot: ck.Robot, crate: ck.Obstacle) -> ck.CollisionWorld:
    return ck.CollisionWorld(robot, [crate])


@pytest.fixture()
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


def random_configurations(robot: ck.Robot, rng: np.random.Generator, n: int) -> np.ndarray:
    return rng.uniform(robot.limits.lower, robot.limits.upper, (n, robot.nq))
