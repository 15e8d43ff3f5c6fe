"""The last resort: the sampling planner's path followed through its vertices, verified like any plan."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.narrow_passages import narrow_scene
from planning.bench.scene_generator import generate_scenes
from planning.curves.trajectory import Trajectory
from planning.pipeline import path_following
from planning.pipeline.choose import Choice, Refusal
from planning.pipeline.deadline import Deadline
from planning.pipeline.path_following import follow_path, shortened, stop_and_go_timing, through_vertices
from planning.pipeline.path_seeds import clearance_validity, sampled_path
from planning.pipeline.planner import plan
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.timing import FixedDuration, FreeDuration


@pytest.fixture(scope="module")
def window(robot: ck.Robot) -> Problem:
    """A window in a wall across the swing: the straight line is blocked."""
    return build_problem(narrow_scene(np.random.default_rng(5), robot, "window"), robot)


def test_a_sampled_path_is_followed_by_a_spline_through_its_vertices_sooner_than_stopping(
    window: Problem,
) -> None:
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    problem, followed = follow_path(window, found.path)
    assert isinstance(followed, Choice) and followed.verification.accepted
    assert followed.timing.method == "through_path" and not followed.timing.stretched
    path = shortened(window, found.path)  # the path followed
    np.testing.assert_array_equal(followed.nodes, window.configurations(path))
    fit = followed.timing.fit.trajectory  # the spline before its timing passes through every vertex
    passed = fit(fit.knots)
    for vertex in followed.nodes:
        assert np.abs(passed - vertex).max(axis=1).min() < 1e-9
    for stopping in (path, found.path):
        assert (
            followed.timing.trajectory.duration
            < stop_and_go_timing(window, window.configurations(stopping)).trajectory.duration
        )
    assert problem.scene.planner.waypoints == max(1, len(path) - 2)
    assert followed.x.size == problem.objective.lower.size


def test_the_path_followed_is_shorter_its_vertices_clear_and_drawn_from_the_plans_seed(
    window: Problem,
) -> None:
    """The shortcuts end where the path ends, shorten it (the joints' weighted length), keep the
    fitness's clearance at every vertex (a shortcut's start too, a point between two checked
    configurations of an edge), and draw from the plan's seed."""
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    path = shortened(window, found.path)
    np.testing.assert_array_equal(path[[0, -1]], found.path[[0, -1]])
    weights = ck.path_weights(window.robot)[window.moving]

    def length(polyline: np.ndarray) -> float:
        return float(np.abs(np.diff(polyline, axis=0)).sum(axis=0) @ weights)

    assert length(path) < length(found.path)
    valid = clearance_validity(window)
    assert all(valid(vertex[None])[0] for vertex in path)
    np.testing.assert_array_equal(shortened(window, found.path), path)
    reseeded = dataclasses.replace(
        window, scene=window.scene.with_planner(seed=window.scene.planner.seed + 1)
    )
    assert not np.array_equal(shortened(reseeded, found.path), path)


def test_the_spline_through_a_path_meets_its_points_on_centripetal_knots(window: Problem) -> None:
    """Each piece split into ``points`` equal parts, met exactly; each part's time the square
    root of its weighted length (the nominal duration spread over them)."""
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    vertices = window.configurations(found.path)
    weights = ck.path_weights(window.robot)[window.moving]
    timing = through_vertices(window, vertices, weights, 3)
    fit = timing.fit.trajectory
    assert fit.n_segments == 3 * (len(vertices) - 1)
    met = fit(fit.knots)
    np.testing.assert_allclose(met[::3], vertices, atol=1e-9)
    np.testing.assert_allclose(
        met[1::3][: len(vertices) - 1], vertices[:-1] + np.diff(vertices, axis=0) / 3, atol=1e-9
    )
    parts = np.abs(np.diff(met[:, window.moving], axis=0)) @ weights
    steps = np.diff(fit.knots)
    np.testing.assert_allclose(steps / steps.sum(), np.sqrt(parts) / np.sqrt(parts).sum(), rtol=1e-9)
    np.testing.assert_allclose(fit.knots[-1], window.duration.nominal_duration(len(steps)))


def test_the_path_as_it_is_when_no_spline_is_tried_stops_at_every_vertex(
    window: Problem, monkeypatch: pytest.MonkeyPatch
) -> None:
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    monkeypatch.setattr(path_following, "POINTS_PER_PIECE", ())
    _, followed = follow_path(window, found.path)
    assert isinstance(followed, Choice) and followed.verification.accepted
    assert followed.timing.method == "stop_and_go" and followed.candidates_timed == 1
    trajectory = followed.timing.trajectory
    reached = trajectory(trajectory.knots)[:, window.moving]
    for vertex in found.path:  # every vertex is a knot of the motion, where it stands still
        k = int(np.argmin(np.abs(reached - vertex).max(axis=1)))
        assert np.abs(reached[k] - vertex).max() < 1e-9
        assert np.abs(trajectory(trajectory.knots[k], 1)).max() < 1e-9


def test_a_fixed_duration_is_kept_by_the_spline_through_the_path(window: Problem) -> None:
    """A scene's fixed duration that the path can be followed within: the spline through it
    takes exactly that long, within the limits, as fast as stopping at every vertex would."""
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    stopping = stop_and_go_timing(window, window.configurations(found.path)).trajectory.duration
    fixed = dataclasses.replace(window, duration=FixedDuration(2.0 * stopping))
    _, followed = follow_path(fixed, found.path)
    assert isinstance(followed, Choice) and followed.verification.accepted
    assert followed.timing.method == "through_path" and not followed.timing.stretched
    assert followed.timing.trajectory.duration == pytest.approx(2.0 * stopping)


def test_past_the_deadline_no_spline_is_tried(window: Problem) -> None:
    found = sampled_path(window, np.random.default_rng(3))
    assert found is not None
    spent = dataclasses.replace(window, deadline=Deadline(at_s=0.0, limit_s=1.0))
    _, followed = follow_path(spent, found.path)
    assert isinstance(followed, Choice) and followed.timing.method == "stop_and_go"


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
    assert result.metrics.timing == "through_path"
    same = plan(dataclasses.replace(scene, planner=planner), robot)
    np.testing.assert_array_equal(same.trajectory.coefficients, result.trajectory.coefficients)
