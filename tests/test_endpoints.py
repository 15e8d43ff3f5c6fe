"""A scene's ends: the IK's solution clear of the margins, a preferred one first, in one search."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.bench.arm_scenes import blocked_scene
from planning.io.scene_file import parse_scene
from planning.pipeline.endpoints import endpoint, margin_violation
from planning.pipeline.problem import scene_world


@pytest.fixture(scope="module")
def ur5() -> ck.Robot:
    return ck.load_robot(example_robot("ur5"))


def test_a_preferred_goal_comes_first_and_the_nearest_clear_one_without_it(
    ur5: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = parse_scene(blocked_scene("ur5_0", "ur5", ur5, 0, margin_m=0.03))
    world = scene_world(scene, ur5)
    q_start = endpoint(world, scene, "start")
    searches: list[Any] = []
    real = ck.solve_ik

    def counted(*args: Any, **kwargs: Any) -> Any:
        searches.append(kwargs.get("prefer"))
        return real(*args, **kwargs)

    monkeypatch.setattr(ck, "solve_ik", counted)
    nearest = endpoint(world, scene, "goal", seed_q=q_start)
    assert len(searches) == 1 and margin_violation(world, scene, nearest) is None

    def flipped(q: np.ndarray) -> bool:  # the shoulder turned away from the nearest goal's
        return bool(abs(q[0] - nearest[0]) > 1.0)

    preferred = endpoint(world, scene, "goal", seed_q=q_start, preferred=flipped)
    assert len(searches) == 2 and flipped(preferred) and margin_violation(world, scene, preferred) is None
    assert scene.goal.pose is not None
    for q in (nearest, preferred):  # both reach the goal's position (forward kinematics)
        reached = ck.frame_poses(ur5, q[None])[0]
        assert np.linalg.norm(reached[:3, 3] - np.asarray(scene.goal.pose[0])) <= 1e-4
    fallback = endpoint(world, scene, "goal", seed_q=q_start, preferred=lambda q: False)
    assert len(searches) == 3  # one search, not a second one without the preference
    assert margin_violation(world, scene, fallback) is None
    weights = ck.path_weights(ur5)  # the nearest clear solution of a search that drew more starts
    assert weights @ np.abs(fallback - q_start) <= weights @ np.abs(nearest - q_start)
    np.testing.assert_allclose(fallback, nearest, atol=0.01)  # on the same branch
