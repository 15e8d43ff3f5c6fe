"""The last resort: the sampling planner's path followed vertex to vertex, verified like any plan."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.narrow_passages import narrow_scene
from planning.bench.scene_generator import generate_scenes
from planning.curves.trajectory import Trajectory
from planning.pipeline.choose import Choice, Refusal
from planning.pipeline.path_following import follow_path
from planning.pipeline.path_seeds import sampled_path
from planning.pipeline.planner import plan
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.timing import FixedDuration, FreeDuration


@pytest.fixture(scope="module")
def window(robot: ck.Robot) -> Problem:
    """A window in a wall across the swing: the straight line is blocked."""
    return build_problem(narrow_scene(np.random.default_rng(5), robot, "window"), robot)


def test_a_sampled_path_is_followed_through_its_vertices_and_verified(window: Problem) -> None:
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    problem, followed = follow_path(window, found.path)
    assert isinstance(followed, Choice) and followed.verification.accepted
    assert followed.timing.method == "stop_and_go" and not followed.timing.stretched
    trajectory = followed.timing.trajectory
    reached = trajectory(trajectory.knots)[:, window.moving]
    for vertex in found.path:  # every vertex is a knot of the motion, where it stands still
        k = int(np.argmin(np.abs(reached - vertex).max(axis=1)))
        assert np.abs(reached[k] - vertex).max() < 1e-9
        assert np.abs(trajectory(trajectory.knots[k], 1)).max() < 1e-9
    assert problem.scene.planner.waypoints == max(1, len(found.path) - 2)
    assert followed.x.size == problem.objective.lower.size


def test_a_path_through_an_obstacle_is_refused_with_the_reason(window: Problem) -> None:
    straight = np.array([window.q_start[window.moving], window.q_goal[window.moving]])
    _, followed = follow_path(window, straight)
    assert isinstance(followed, Refusal)
    assert followed.cause.startswith("following it vertex to vertex") and "obstacle" in followed.cause


def test_a_fixed_duration_holds_a_motion_that_fits_and_reports_one_that_does_not() -> None:
    motion = Trajectory(np.array([0.0, 2.0]), np.array([[[0.0, 0.0, 0.75, -0.25]]]))  # rest to rest, 0 -> 1
    slowed, stretched = FixedDuration(4.0).held(motion)
    assert slowed.duration == pytest.approx(4.0) and not stretched
    np.testing.assert_allclose(
        slowed(np.array([0.0, 2.0, 4.0]))[:, 0], motion(np.array([0.0, 1.0, 2.0]))[:, 0]
    )
    kept, stretched = FixedDuration(1.0).held(motion)
    assert kept is motion and stretched
    assert FreeDuration().held(motion) == (motion, False)


def spline_touching_scene(robot: ck.Robot) -> Scene:
    """A narrow scene whose splines all touch the passage without the refinement (issue 33, B.3).

    RRT-Connect's path is drawn from uniform samples only and not straightened joint by joint,
    as when the scene was found, and seeded by its corners' placement alone.
    """
    scene = next(s for s in generate_scenes(40, 77, robot, narrow=10) if s.name == "scene_028")
    tuning = scene.planner.tuning
    seeding = dataclasses.replace(tuning.seeding, local_share=0.0, joint_shortcuts=0, placements=(0.0,))
    uniform = dataclasses.replace(tuning, seeding=seeding)
    return dataclasses.replace(scene, planner=dataclasses.replace(scene.planner, tuning=uniform))


def test_a_scene_whose_splines_all_touch_the_passage_is_planned_not_refused(robot: ck.Robot) -> None:
    """A false "no solution" of issue 33 (B.3): the splines near the passage failed; the path did not.

    The default search now repairs its best spline there; without the refinement every
    spline still touches the passage, and the last resort follows the path (RRT-Connect's
    path drawn from uniform samples only, as when the scene was found, and seeded by its
    corners' placement alone: the firefly finds a spline through the evenly spaced one).
    """
    scene = spline_touching_scene(robot)
    for planner in (scene.planner, scene.planner.updated(refine="none")):
        result = plan(dataclasses.replace(scene, planner=planner), robot)
        assert result.verification.accepted
        assert result.metrics.min_clearance_m >= scene.safety_margin
    assert result.metrics.timing == "stop_and_go"
    same = plan(dataclasses.replace(scene, planner=planner), robot)
    np.testing.assert_array_equal(same.trajectory.coefficients, result.trajectory.coefficients)
