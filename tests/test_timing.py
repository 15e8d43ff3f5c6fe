from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import cpr_kin as ck
from planning import build_problem
from planning.bench.scene_generator import generate_scenes
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import paper_scene
from planning.io.trajectory_io import trajectory_document
from planning.pipeline.choose import Choice, beyond_margin, choose, verify
from planning.pipeline.planner import plan, solve
from planning.pipeline.result import PlanResult
from planning.pipeline.timing import least_uniform_scale, narrowed_timings, uniform_scale
from planning.pipeline.tuning import SearchTuning
from planning.search.optimizer import SearchResult

NARROWED_ACCELERATION = SearchTuning().narrowed_acceleration


@pytest.fixture(scope="module")
def free_results(robot: ck.Robot) -> list[PlanResult]:
    """Plans of generated scenes, whose duration is free: timed as fast as the limits allow."""
    results = []
    for scene in generate_scenes(6, 5, robot):
        assert scene.duration is None
        try:
            results.append(plan(scene, robot))
        except (PlanningError, NoSolutionError):
            continue
    assert len(results) >= 5
    return results


def test_free_durations_are_timed_within_the_limits_c3_and_certified(
    robot: ck.Robot, free_results: list[PlanResult]
) -> None:
    limits = robot.limits
    for result in free_results:
        trajectory, metrics = result.trajectory, result.metrics
        assert result.verification.accepted and metrics.min_clearance_m >= result.scene.safety_margin
        used = [
            float(np.max(trajectory.extrema(r).peak / limit))
            for r, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1)
        ]
        assert all(u <= 1.0 + 1e-9 for u in used)
        # a limit is reached: the acceleration's own, or its share for a narrowed timing
        shares = NARROWED_ACCELERATION if metrics.timing == "narrowed" else (1.0,)
        reached = [max(used[0], used[1] / share, used[2]) for share in shares]
        assert any(peak == pytest.approx(1.0, abs=1e-9) for peak in reached)
        positions = trajectory.extrema(0)
        assert np.all(positions.minimum >= limits.lower - 1e-9) and np.all(
            positions.maximum <= limits.upper + 1e-9
        )
        jump, relative = trajectory.knot_jumps(4)
        assert np.all((relative < 1e-7) | (jump < 1e-7))  # C3 at every knot (a break would be O(1))
        np.testing.assert_allclose(
            trajectory(trajectory.knots[[0, -1]]), [result.problem.q_start, result.problem.q_goal], atol=1e-12
        )
        for r in (1, 2):  # at rest at both ends
            np.testing.assert_allclose(trajectory(trajectory.knots[[0, -1]], r), 0.0, atol=1e-9)


def test_the_fastest_timing_is_never_longer_than_the_uniform_one(free_results: list[PlanResult]) -> None:
    methods = []
    for result in free_results:
        uniform = result.spline.trajectory.time_scaled(uniform_scale(result.spline, result.problem))
        assert result.trajectory.duration <= uniform.duration * (1 + 1e-12)
        methods.append(result.metrics.timing)
        if result.metrics.timing == "fastest":  # by 15-35 % on these scenes
            assert result.trajectory.duration < uniform.duration
    assert methods.count("fastest") >= len(methods) - 1


def test_timings_are_offered_fastest_first(robot: ck.Robot, free_results: list[PlanResult]) -> None:
    result = free_results[0]
    offered = result.problem.duration.timings(result.problem, result.waypoints)
    assert [t.method for t in offered.all] == ["fastest", "uniform"]
    assert offered.all[0].trajectory.duration <= offered.all[1].trajectory.duration
    fixed = build_problem(paper_scene(0), robot)
    (only,) = fixed.duration.timings(fixed, solve(fixed).waypoints).all
    assert only.method == "fixed" and only.trajectory.duration == pytest.approx(4.0)


def test_the_uniform_timing_is_computed_only_when_asked_for_unless_it_may_be_shorter(
    free_results: list[PlanResult],
) -> None:
    """The sampled bound is below the exact scale and within a per cent of it; the fastest
    timing shorter than that bound, the uniform one waits until asked for, and is then the
    one computed at once (the same trajectory)."""
    for result in free_results:
        problem, fit = result.problem, result.spline
        least, exact = least_uniform_scale(fit, problem), uniform_scale(fit, problem)
        assert exact * 0.99 <= least <= exact
        offered = problem.duration.timings(problem, result.waypoints)
        assert offered.first.method == "fastest"
        assert "others" not in vars(offered)  # not computed yet (functools.cached_property)
        (uniform,) = offered.others
        assert uniform.method == "uniform" and offered.of("uniform") is uniform
        assert uniform.trajectory.duration == pytest.approx(fit.trajectory.duration * exact, rel=1e-12)
        assert offered.first.trajectory.duration < uniform.trajectory.duration


def test_narrowed_timings_meet_the_lowered_acceleration_and_beat_the_uniform_one(
    robot: ck.Robot, free_results: list[PlanResult]
) -> None:
    limits = robot.limits
    result = free_results[0]
    offered = result.problem.duration.timings(result.problem, result.waypoints)
    uniform = next(t for t in offered.all if t.method == "uniform").trajectory
    narrowed = narrowed_timings(result.problem, offered, NARROWED_ACCELERATION)
    assert narrowed, "a share of 0.7 costs well under the uniform timing's 15-35 %"
    durations = [timing.trajectory.duration for timing in narrowed]
    assert durations == sorted(durations) and durations[-1] < uniform.duration
    for share, timing in zip(NARROWED_ACCELERATION, narrowed, strict=False):
        trajectory = timing.trajectory
        assert timing.method == "narrowed" and timing.fit is offered.first.fit
        used = [
            float(np.max(trajectory.extrema(r).peak / limit))
            for r, limit in enumerate((limits.velocity, share * limits.acceleration, limits.jerk), start=1)
        ]
        assert max(used) == pytest.approx(1.0, abs=1e-9) and all(u <= 1.0 + 1e-9 for u in used)
        np.testing.assert_allclose(
            trajectory(trajectory.knots[[0, -1]]), [result.problem.q_start, result.problem.q_goal], atol=1e-12
        )
    fixed = build_problem(paper_scene(0), robot)
    assert (
        narrowed_timings(fixed, fixed.duration.timings(fixed, solve(fixed).waypoints), NARROWED_ACCELERATION)
        == []
    )


def _alone(x: np.ndarray, fitness: float) -> SearchResult:
    """A search that found ``x`` and nothing else."""
    history = np.array([fitness])
    return SearchResult(x, fitness, 1, history, history, np.array([1]), x[None], history)


def test_a_path_whose_fastest_timing_cuts_into_the_margin_runs_narrowed(
    robot: ck.Robot, free_results: list[PlanResult]
) -> None:
    """A planned path, its margin raised between the certified clearance of its fastest timing
    and that of its first narrowed one (which swings wider or tighter by a millimetre or so):
    the choice falls to the narrowed timing, which passes and is shorter than the uniform one.
    Built from the plan rather than found in a scene: which scene's fastest timing cuts the
    margin depends on the machine's floating point."""
    cases = 0
    for result in free_results:
        problem = result.problem
        offered = problem.duration.timings(problem, result.waypoints)
        narrowed = narrowed_timings(problem, offered, NARROWED_ACCELERATION)
        fastest_m = verify(problem, offered.first.trajectory, offered.first.fit).check.certified_min_m
        narrowed_m = verify(problem, narrowed[0].trajectory, narrowed[0].fit).check.certified_min_m
        if narrowed_m < fastest_m + 5e-4:
            continue
        cases += 1
        margin_m = 0.5 * (fastest_m + narrowed_m)
        raised = build_problem(dataclasses.replace(result.scene, safety_margin=margin_m), robot)
        x = result.waypoints[1:-1][:, raised.moving].ravel()
        np.testing.assert_array_equal(raised.objective.nodes(x[None])[0], result.waypoints)
        alone = _alone(x, float(raised.objective(x[None])[0]))
        chosen = choose(raised, alone, beyond_margin(raised, alone))
        assert isinstance(chosen, Choice) and chosen.timing.method == "narrowed"
        assert chosen.verification.accepted and chosen.verification.check.certified_min_m >= margin_m
        assert not verify(raised, offered.first.trajectory, offered.first.fit).accepted
        uniform = next(t for t in offered.all if t.method == "uniform").trajectory
        assert chosen.timing.trajectory.duration < uniform.duration
        jump, relative = chosen.timing.trajectory.knot_jumps(4)
        assert np.all((relative < 1e-7) | (jump < 1e-7))
    assert cases >= 2, "a narrowed timing swings at least 0.5 mm wider than the fastest on some paths"


def test_the_search_ranks_candidates_by_a_bound_tight_to_the_executed_duration(
    free_results: list[PlanResult],
) -> None:
    """The fitness's time term (phase plane of the sampled path plus the jerk window's tail,
    :mod:`planning.curves.jerk_window`) is what the fastest timing of the chosen path takes:
    at most 5 % below it (the check samples are coarser than the timing's grid), the median
    within 2 % (a constant allowance of ``1.25 a / j`` is 4 % short in the median), and at
    most 20 % above (where the timing's velocity caps find a faster motion than the widened
    window)."""
    ratios = []
    for result in free_results:
        fastest = result.problem.duration.timings(result.problem, result.waypoints).first
        assert fastest.method == "fastest"
        ratios.append(float(result.breakdown.duration_s[0]) / fastest.trajectory.duration)
    assert all(0.95 <= ratio <= 1.2 for ratio in ratios), ratios
    assert abs(float(np.median(ratios)) - 1.0) < 0.02, ratios


def test_same_seed_gives_a_byte_identical_trajectory_file(
    robot: ck.Robot, free_results: list[PlanResult]
) -> None:
    again = plan(free_results[0].scene, robot)
    first = json.dumps(trajectory_document(free_results[0], timings=False))
    assert json.dumps(trajectory_document(again, timings=False)) == first
