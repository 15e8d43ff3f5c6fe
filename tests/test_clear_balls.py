"""What the meshes' tests measured answers the later ones near it: by the bound alone, never wrongly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.collision.clear_balls import ClearBalls
from cpr_kin.collision.decisive import coal_error_m
from tests.test_exact_pairs import UR10


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))


def test_a_measured_configuration_clears_the_ball_its_distance_allows() -> None:
    # pair 0 moves with joints 0 and 2 at 0.5 and 0.25 m/rad; measured 0.03 m apart at the origin
    balls = ClearBalls(np.array([[0.5, 0.0, 0.25], [0.0, 1.0, 0.0]]), kept=2)
    origin = np.zeros(3)
    assert not balls.clear(0, origin, 0.01)  # nothing measured yet
    balls.add(0, origin, 0.03)
    room_m = 0.03 - coal_error_m(0.03) - 0.01
    assert balls.clear(0, np.array([0.99 * room_m / 0.5, 5.0, 0.0]), 0.01)  # joint 1 does not move it
    assert not balls.clear(0, np.array([1.01 * room_m / 0.5, 0.0, 0.0]), 0.01)
    assert balls.clear(0, np.array([0.0, 0.0, 0.99 * room_m / 0.25]), 0.01)
    assert not balls.clear(0, np.array([0.5 * room_m / 0.5, 0.0, 0.51 * room_m / 0.25]), 0.01)
    assert not balls.clear(0, origin, 0.03)  # not beyond what was measured
    assert not balls.clear(1, origin, 0.0)  # another pair's memory is its own
    assert balls.answered == 2


def test_the_oldest_measurement_goes_when_more_are_kept() -> None:
    balls = ClearBalls(np.array([[1.0]]), kept=2)
    for centre in (0.0, 1.0, 2.0):
        balls.add(0, np.array([centre]), 0.1)
    assert not balls.clear(0, np.array([0.0]), 0.0)
    assert balls.clear(0, np.array([1.0]), 0.0) and balls.clear(0, np.array([2.05]), 0.0)


def test_the_self_test_on_the_meshes_answers_as_their_distances_where_the_memory_answers() -> None:
    """A UR10 without an SRDF, its wrist folded by its forearm: the hulls flag, the meshes clear.

    Configurations about a few folded ones (as a search's candidates come back to a region):
    the margin test, which asks the memory first, gives the verdict of the meshes' distances
    (measured without it, by the closest pairs' search), and the memory answers many of them.
    """
    robot = ck.load_robot(UR10)
    world = ck.CollisionWorld(robot, [])
    rng = np.random.default_rng(108)
    folded = np.array([1.25, -2.2, 0.98, 2.25, 3.46, -2.76])  # a start of a generated scene
    centres = folded + rng.normal(0.0, 0.3, (4, robot.nq))
    q = np.clip(
        np.repeat(centres, 60, axis=0) + rng.normal(0.0, 0.03, (240, robot.nq)),
        robot.limits.lower,
        robot.limits.upper,
    )
    distances_m = world.self_collision.distances(q)[0]
    for margin_m in (0.0025, 0.011):
        np.testing.assert_array_equal(world.self_collision.violated(q, margin_m), distances_m < margin_m)
    measured = world.self_collision._exact._measured  # the memory is the world's own
    assert isinstance(measured, ClearBalls) and measured.answered > 50
