"""The search's seeds: the straight line when clear, a sampled path around what blocks it."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.narrow_passages import narrow_scene
from planning.errors import PlanningError
from planning.io.scene_file import parse_scene
from planning.pipeline.path_seeds import clearance_validity, sampled_path
from planning.pipeline.problem import Problem, build_problem, finer_step_m, with_planner
from planning.pipeline.scene import Scene
from planning.pipeline.seeding import PathSeeding, seed_search
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target
from planning.pipeline.tuning import SearchTuning, SeedingTuning
from planning.pipeline.verification import Requirements, verify_for_scene, verify_trajectory
from planning.search.edges import ScreenedValidity, screen_of
from planning.search.waypoints import evenly_along, placements_along, waypoints_along


@pytest.fixture(scope="module")
def window(robot: ck.Robot) -> Problem:
    """A window in a wall across the swing: the straight line is blocked."""
    scene = narrow_scene(np.random.default_rng(5), robot, "window")
    return build_problem(scene, robot)


def test_a_clear_straight_line_is_the_only_path_seed(robot: ck.Robot) -> None:
    scene = Scene(start=Target(tcp=(0.5, 0.3, 0.3)), goal=Target(tcp=(0.3, 0.5, 0.4)))
    problem = build_problem(scene, robot)
    seeds = seed_search(problem)
    assert seeds.straight_line_clear and seeds.path is None and seeds.problem is problem
    assert seeds.feasible  # the search refines the straight line at once
    np.testing.assert_array_equal(seeds.candidates[0], problem.objective.straight_line())
    assert len(seeds.candidates) == int(SeedingTuning().share * scene.planner.firefly.fireflies)
    objective = problem.objective
    assert np.all((seeds.candidates >= objective.lower) & (seeds.candidates <= objective.upper))
    # the others are small moves around the seed
    spread = np.abs(seeds.candidates[1:] - seeds.candidates[0]) / (objective.upper - objective.lower)
    assert 0.0 < np.median(spread) < 0.05


def test_a_blocked_line_is_seeded_with_a_clear_sampled_path(robot: ck.Robot, window: Problem) -> None:
    seeds = seed_search(window)
    assert not seeds.straight_line_clear and seeds.path is not None
    moving = window.moving
    np.testing.assert_allclose(seeds.path[0], window.q_start[moving])
    np.testing.assert_allclose(seeds.path[-1], window.q_goal[moving])
    # every vertex keeps the fitness's clearance, by coal's own distance
    full = np.repeat(window.q_start[None], len(seeds.path), axis=0)
    full[:, moving] = seeds.path
    clearance = window.world.clearance_batch(full).min_clearance_m
    assert clearance.min() >= window.objective.required_m - 1e-9
    # the straight line, then the path's waypoints
    np.testing.assert_array_equal(seeds.candidates[0], seeds.problem.objective.straight_line())
    assert seeds.candidates.shape[1] == seeds.problem.objective.dimension
    # feasible as the path's seed is
    objective = seeds.problem.objective
    assert seeds.feasible == bool(objective.feasible(objective(seeds.candidates[1:2])[0]))


def test_more_waypoints_follow_the_path_until_the_spline_keeps_the_clearance(window: Problem) -> None:
    first = seed_search(window)
    wider = seed_search(window, more_waypoints=True, path=first.path)
    assert wider.problem.scene.planner.waypoints >= window.scene.planner.waypoints + 2
    assert wider.problem.world is window.world  # the same world, a new objective
    fitness = wider.problem.objective(wider.candidates[1][None])[0]
    assert fitness <= wider.problem.objective.t_max  # this window's path seed is feasible with more


def test_same_seed_same_seeds_and_the_sampler_has_its_own_stream(window: Problem) -> None:
    a, b = seed_search(window), seed_search(window)
    np.testing.assert_array_equal(a.candidates, b.candidates)
    other = window.scene.with_planner(seed=1)
    c = seed_search(build_problem(other, window.robot))
    assert not np.array_equal(a.candidates, c.candidates)
    # the sampled path comes from default_rng([seed, 1]), not the firefly's default_rng(seed)
    path = sampled_path(window, np.random.default_rng([window.scene.planner.seed, 1]))
    assert path is not None
    np.testing.assert_array_equal(path.path, a.path)


def drawn_paths(problem: Problem) -> list[tuple[np.ndarray, float]]:
    """The paths the seeding may draw, in order, each with the fitness of its waypoints' seed."""
    rng = np.random.default_rng([problem.scene.planner.seed, 1])
    weights = ck.motion_radii(problem.robot)[problem.moving]
    drawn = []
    for _ in range(problem.scene.planner.tuning.seeding.path_attempts):
        found = sampled_path(problem, rng)
        assert found is not None
        shares = problem.scene.planner.tuning.seeding.placements
        offered = placements_along(found.path, problem.scene.planner.waypoints, weights, shares)
        drawn.append((found.path, float(problem.objective(offered.reshape(len(shares), -1)).min())))
    return drawn


THREE = 3
"""The waypoints the scenes below were chosen with (the planner's default until stop 67)."""


def uniform_samples(problem: Problem, **seeding: Any) -> Problem:
    """``problem`` whose RRT-Connect draws uniform samples only and straightens no joint of its
    paths, with :data:`THREE` waypoints (as when these scenes were chosen)."""
    tuning = SearchTuning(seeding=SeedingTuning(local_share=0.0, joint_shortcuts=0, **seeding))
    return with_planner(problem, waypoints=THREE, tuning=tuning)


def test_a_path_whose_spline_violates_the_clearance_is_drawn_again(robot: ck.Robot) -> None:
    """A beam: the spline through the first path's waypoints cuts into the margin, the second's not."""
    problem = uniform_samples(build_problem(narrow_scene(np.random.default_rng(6), robot, "beam"), robot))
    drawn = drawn_paths(problem)
    (first, first_fitness), (second, second_fitness) = drawn[:2]
    assert first_fitness > problem.objective.t_max >= second_fitness
    seeds = seed_search(problem)
    np.testing.assert_array_equal(seeds.path, second)
    assert seeds.problem is problem  # a feasible seed with the scene's waypoints: no more needed
    one_attempt = uniform_samples(problem, path_attempts=1)  # keeps the first path
    np.testing.assert_array_equal(seed_search(one_attempt).path, first)


def test_a_redraw_gets_what_remains_of_redraw_samples_and_gives_up_beyond(robot: ck.Robot) -> None:
    """The same beam: its first path takes 1 sample, the second (feasible) one 2.

    With ``redraw_samples = 3`` the redraw may take 2 and finds the second path; with 2 it
    may take 1, gives up, and the first path (in hand, its seed infeasible) is kept.
    """
    problem = uniform_samples(build_problem(narrow_scene(np.random.default_rng(6), robot, "beam"), robot))
    rng = np.random.default_rng([problem.scene.planner.seed, 1])
    first, second = sampled_path(problem, rng), sampled_path(problem, rng)
    assert first is not None and second is not None and (first.samples, second.samples) == (1, 2)
    np.testing.assert_array_equal(seed_search(uniform_samples(problem, redraw_samples=3)).path, second.path)
    kept = seed_search(uniform_samples(problem, redraw_samples=2))
    np.testing.assert_array_equal(kept.path, first.path)
    assert not kept.feasible and not kept.no_path


def test_when_no_path_seed_is_feasible_the_best_ranked_is_kept(robot: ck.Robot) -> None:
    # its three draws take 194, 9 and 168 samples: a budget for all three; the corners'
    # placement alone (with the evenly spaced ones offered too, the first path's seed is
    # feasible: test_the_best_placement_along_the_path_seeds_the_search)
    built = build_problem(narrow_scene(np.random.default_rng(3), robot, "pillars"), robot)
    problem = uniform_samples(built, redraw_samples=1_000, placements=(0.0,))
    drawn = drawn_paths(problem)
    fitness = [value for _, value in drawn]
    assert min(fitness) > problem.objective.t_max and int(np.argmin(fitness)) > 0
    np.testing.assert_array_equal(seed_search(problem).path, drawn[int(np.argmin(fitness))][0])


def test_the_best_placement_along_the_path_seeds_the_search(robot: ck.Robot) -> None:
    """A window (seed 7): the spline through the first path's corners cuts into the margin, the
    ones through waypoints evenly spaced along it, or halfway between, do not; the seeding keeps
    the best placement and draws no other path. Offered the corners alone, it finds no feasible
    seed in the draws its budget allows."""
    window = build_problem(narrow_scene(np.random.default_rng(7), robot, "window"), robot)
    built = with_planner(window, waypoints=THREE)
    found = sampled_path(built, np.random.default_rng([built.scene.planner.seed, 1]))
    assert found is not None
    weights = ck.path_weights(robot)[built.moving]
    count, shares = built.scene.planner.waypoints, built.scene.planner.tuning.seeding.placements
    assert shares == (0.0, 0.5, 1.0)
    offered = placements_along(found.path, count, weights, shares)
    objective = built.objective
    fitness = objective(offered.reshape(len(shares), -1))
    assert not objective.feasible(fitness[0]) and objective.feasible(fitness.min())
    np.testing.assert_array_equal(offered[0], waypoints_along(found.path, count, weights))
    seeds = seed_search(built)
    np.testing.assert_array_equal(seeds.path, found.path)  # the first path, not drawn again
    assert seeds.feasible and seeds.problem is built
    assert objective(seeds.candidates[1][None])[0] == fitness.min()
    corners = with_planner(built, tuning=SearchTuning(seeding=SeedingTuning(placements=(0.0,))))
    assert not seed_search(corners).feasible


def test_placements_are_between_the_corners_and_evenly_spaced_waypoints() -> None:
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]])  # arc length 4
    weights = np.ones(2)
    corners = waypoints_along(path, 3, weights)
    even = evenly_along(path, 3, weights)
    np.testing.assert_allclose(even, [[1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])  # at arc 1, 2, 3
    zigzag = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [4.0, 1.0]])  # arc 5: at 1.25, 2.5, 3.75
    np.testing.assert_allclose(evenly_along(zigzag, 3, weights), [[1.25, 0.0], [2.0, 0.5], [2.75, 1.0]])
    offered = placements_along(zigzag, 3, weights, (0.0, 0.25, 1.0))
    np.testing.assert_allclose(offered[0], waypoints_along(zigzag, 3, weights))
    np.testing.assert_allclose(offered[2], evenly_along(zigzag, 3, weights))
    np.testing.assert_allclose(offered[1], 0.75 * offered[0] + 0.25 * offered[2])
    assert np.array_equal(placements_along(path, 3, weights, (0.0,))[0], corners)


def test_placements_are_validated() -> None:
    with pytest.raises(PlanningError, match=r"placements\[1\] = 1.5 .*\[0, 1\]"):
        SeedingTuning(placements=(0.0, 1.5))
    with pytest.raises(PlanningError, match=r"placements = \[\] must hold at least one share"):
        SeedingTuning(placements=())
    assert SeedingTuning(placements=[0.5]).placements == (0.5,)  # type: ignore[arg-type]
    with pytest.raises(PlanningError, match=r"joint_shortcuts = -1 .*\[0, 10000\]"):
        SeedingTuning(joint_shortcuts=-1)


def test_seeding_none_is_a_setting(robot: ck.Robot) -> None:
    assert PlannerSettings().seeding == "paths"
    assert PlannerSettings(seeding="none").seeding == "none"


def test_a_passage_narrower_than_margin_plus_step_is_found_with_a_finer_step(robot: ck.Robot) -> None:
    """Generated scene 43 of seed 13: RRT-Connect finds no path keeping the margin plus the 5 mm
    certified step clear in 10,000 samples (its way passes 2 mm outside the margin; in more,
    an edge checked every 4 cm may slip through); its trees go on at a 1 mm step's
    clearance, and the plan is searched and certified at it."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.planner import plan

    scene = generate_scenes(100, seed=13, robot=robot, narrow=33)[43]
    assert scene.planner.verify_step_m == 0.005
    problem = build_problem(scene, robot)
    strict = with_planner(problem, tuning=SearchTuning(seeding=SeedingTuning(max_samples=10_000)))
    assert seed_search(strict).path is None  # nothing keeps margin + 5 mm clear
    result = plan(scene, robot)
    assert result.scene.planner.verify_step_m == pytest.approx(0.001)
    assert result.verification.accepted and result.metrics.min_clearance_m >= scene.safety_margin


def test_after_finer_after_samples_the_trees_keep_the_finer_clearance(robot: ck.Robot) -> None:
    """Scene 43 of seed 13 again: after ``finer_after`` samples the trees go on keeping the
    finer step's clearance, and the path found so (relaxed) holds it, not the whole step's;
    with no finer step to go to (the step already the smallest allowed), they never do."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.seeding import finer_problem
    from planning.pipeline.settings import VERIFY_STEP_RANGE_M

    scene = generate_scenes(100, seed=13, robot=robot, narrow=33)[43]
    early = SearchTuning(seeding=SeedingTuning(finer_after=300))
    problem = with_planner(build_problem(scene, robot), tuning=early)
    finer = finer_problem(problem)
    assert finer is not None and finer.scene.planner.verify_step_m == 0.001
    found = sampled_path(problem, np.random.default_rng(0), finer=lambda: finer)
    assert found is not None and found.relaxed and found.samples > 300
    dense = np.concatenate([waypoints_along(found.path, 200, ck.path_weights(robot)[problem.moving])])
    keeps = problem.world.keeps_clearance
    assert keeps(
        finer.configurations(dense), finer.objective.required_m, finer.objective.required_self_m
    ).all()
    assert not keeps(problem.configurations(dense), problem.objective.required_m, np.inf).all()
    attempt = PathSeeding().first(problem)
    assert attempt.path is not None and attempt.problem.scene.planner.verify_step_m == 0.001
    smallest = with_planner(problem, verify_step_m=VERIFY_STEP_RANGE_M[0])
    assert finer_problem(smallest) is None  # no finer step than this: the trees keep its clearance


def test_the_finer_problem_is_built_once_and_only_when_the_trees_need_it(window: Problem) -> None:
    from planning.pipeline.seeding import finer_problem, lazy_finer_problem

    built: list[Problem] = []

    def finer() -> Problem:
        made = finer_problem(window)
        assert made is not None
        built.append(made)
        return made

    found = sampled_path(window, np.random.default_rng(3), finer=finer)
    assert found is not None and not found.relaxed and found.samples < SeedingTuning().finer_after
    assert not built  # the draw ended before the trees would keep the finer clearance
    lazy = lazy_finer_problem(window)
    assert lazy is not None and lazy() is lazy()  # built once, kept
    assert lazy().scene.planner == finer().scene.planner  # the same problem as finer_problem's


def test_a_passage_rrt_connect_needs_thousands_of_samples_for_is_planned(robot: ck.Robot) -> None:
    """Generated scene 70 of seed 12 (24 narrow): RRT-Connect on uniform samples needs just over
    3000 for it, the former budget, after which the search had only the blocked straight line;
    with a fifth of its samples drawn about its trees' nodes (the default) it needs fewer."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.planner import plan

    scene = {s.name: s for s in generate_scenes(100, seed=12, robot=robot, narrow=24)}["scene_070"]
    problem = build_problem(scene, robot)
    assert seed_search(problem).path is not None
    assert seed_search(uniform_samples(problem, max_samples=3000)).path is None
    assert seed_search(uniform_samples(problem)).path is not None
    assert (
        seed_search(with_planner(problem, tuning=SearchTuning(seeding=SeedingTuning(max_samples=3000)))).path
        is not None
    )
    result = plan(scene, robot)
    assert result.verification.accepted and result.metrics.min_clearance_m >= scene.safety_margin


def test_a_passage_rrt_connect_needs_tens_of_thousands_of_samples_for_is_planned(robot: ck.Robot) -> None:
    """Generated scene 25 of seed 85: RRT-Connect needs more than 10,000 samples (the former
    budget, after which the plan said "no solution" though OMPL's RRT-Connect finds a path in
    its 5 s); within the default budget it finds one, and the plan is certified."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.planner import plan

    scene = generate_scenes(26, seed=85, robot=robot)[25]
    problem = build_problem(scene, robot)
    former = SearchTuning(seeding=SeedingTuning(max_samples=10_000))
    assert seed_search(with_planner(problem, tuning=former), finer=True).no_path
    assert SeedingTuning().max_samples > 10_000
    result = plan(scene, robot)
    assert result.verification.accepted and result.metrics.min_clearance_m >= scene.safety_margin


def test_a_goal_within_margin_plus_step_plans_with_the_finer_step_at_once(robot: ck.Robot) -> None:
    """A goal 2 mm from a ball, margin 0 (a grasp): RRT-Connect at margin plus 5 mm cannot end there."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.planner import plan

    corners = PlannerSettings(waypoints=THREE, tuning=SearchTuning(seeding=SeedingTuning(placements=(0.0,))))
    # the corners' placement, whose path approaches the goal fast enough that the scene's
    # step cannot certify its last 2 mm (below)
    scene = dataclasses.replace(generate_scenes(1, 5, robot)[0], safety_margin=0.0, planner=corners)
    q_goal = build_problem(scene, robot).q_goal
    tool = ck.frame_poses(robot, q_goal[None])[0, :3, 3]
    probe = ck.Obstacle.sphere(0.02, tuple(tool + np.array([0.0, 0.0, 0.25])), name="ball")
    gap = ck.CollisionWorld(robot, [probe]).clearance_batch(q_goal[None]).clearance_m.min()
    ball = ck.Obstacle.sphere(0.02 + gap - 0.002, probe.xyz, name="ball")  # 2 mm from the goal
    near = dataclasses.replace(scene, obstacles=(*scene.obstacles, ball))
    problem = build_problem(near, robot)
    assert problem.world.margin_violated(q_goal[None], problem.objective.required_m)[0]
    assert not problem.world.margin_violated(q_goal[None], 0.0)[0]
    result = plan(near, robot)
    assert result.verification.accepted and result.verification.certified_min_m >= 0.0
    assert result.problem.scene.planner.verify_step_m == scene.planner.finer_verify_step_m
    # cpr-plan check: the scene's 5 mm step cannot certify the last 2 mm; the finer step does
    at_scene_step = verify_trajectory(problem.world, result.trajectory, Requirements.of(problem, True))
    assert not at_scene_step.check.accepted
    assert verify_for_scene(problem, result.trajectory).problems == ()


def test_a_goal_closer_than_the_finer_step_plans_with_half_its_clearance(robot: ck.Robot) -> None:
    """A goal 0.6 mm from a ball, margin 0: even 1 mm beyond the margin leaves it no path."""
    from planning.bench.scene_generator import generate_scenes
    from planning.pipeline.planner import plan

    corners = PlannerSettings(tuning=SearchTuning(seeding=SeedingTuning(placements=(0.0,))))
    # the corners' placement, whose path approaches the goal fast enough that the scene's
    # step cannot certify its last 2 mm (below)
    scene = dataclasses.replace(generate_scenes(1, 5, robot)[0], safety_margin=0.0, planner=corners)
    far = build_problem(scene, robot)
    assert finer_step_m(far) == scene.planner.finer_verify_step_m  # the ends lie centimetres away
    tool = ck.frame_poses(robot, far.q_goal[None])[0, :3, 3]
    probe = ck.Obstacle.sphere(0.02, tuple(tool + np.array([0.0, 0.0, 0.25])), name="ball")
    gap = ck.CollisionWorld(robot, [probe]).clearance_batch(far.q_goal[None]).clearance_m.min()
    ball = ck.Obstacle.sphere(0.02 + gap - 0.0006, probe.xyz, name="ball")
    near = dataclasses.replace(scene, obstacles=(*scene.obstacles, ball))
    problem = build_problem(near, robot)
    clearance = float(problem.world.min_clearance_batch(problem.q_goal[None])[0][0])
    assert clearance == pytest.approx(0.0006, abs=1e-6)
    assert finer_step_m(problem) == pytest.approx(clearance / 2)
    result = plan(near, robot)
    assert result.verification.accepted and result.verification.certified_min_m >= 0.0
    assert result.problem.scene.planner.verify_step_m == pytest.approx(clearance / 2)


def test_where_rrt_connect_found_no_path_the_next_attempts_do_not_ask_again(
    window: Problem, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Its draws are seeded and the clearance it keeps is the same: it would fail alike.

    With one sample RRT-Connect finds no way through the window, at the whole step nor (its
    trees going on) at the finer one; the attempts after the first search from the straight
    line without it: where a search found a feasible candidate the certified check refused,
    with twice the fitness samples; where it found none, there is no next attempt (below).
    """
    from planning.pipeline import path_seeds
    from planning.search.optimizer import SearchResult

    drawn: list[object] = []

    def counted(*args: Any, **kwargs: Any) -> object:
        found = sampled_path(*args, **kwargs)
        drawn.append(found)
        return found

    monkeypatch.setattr(path_seeds, "sampled_path", counted)
    one_sample = with_planner(window, tuning=SearchTuning(seeding=SeedingTuning(max_samples=1)))
    attempt = PathSeeding().first(one_sample)
    assert drawn == [None] and attempt.no_path and "no RRT-Connect path keeps" in attempt.tried
    assert attempt.seeds is not None
    refused = SearchResult.of_point(attempt.seeds[0], 0.5 * attempt.problem.objective.feasible_below, 1)
    for number in (1, 2):  # the retries
        following = PathSeeding().after(attempt, refused)
        assert following is not None and following.number == number
        assert following.no_path and following.path is None and following.tried == attempt.tried
        attempt = following
    assert len(drawn) == 1  # not asked again
    blocked = seed_search(one_sample, sample=False)
    assert blocked.path is None and not blocked.no_path and len(drawn) == 1
    assert seed_search(one_sample).no_path and len(drawn) == 2
    few = with_planner(window, tuning=SearchTuning(seeding=SeedingTuning(max_samples=2, finer_after=1)))
    assert "keeps 0.055 m clear (nor 0.051 m after 1) in 2 samples" in PathSeeding().first(few).tried


def test_without_a_path_a_search_with_nothing_feasible_is_not_repeated(window: Problem) -> None:
    """More waypoints need a path to follow: without one the next attempt would search again
    from the same seeds with the same draws (``default_rng(seed)``) and find the same."""
    from planning.pipeline.search import search

    tuning = SearchTuning(seeding=SeedingTuning(max_samples=1))
    attempt = PathSeeding().first(with_planner(window, tuning=tuning, fireflies=4, iterations=1))
    searched = search(attempt, None, None)
    assert attempt.no_path and not attempt.problem.objective.feasible(searched.fitness)
    again = seed_search(attempt.problem, more_waypoints=True, sample=False)  # what a retry would search
    assert attempt.seeds is not None and again.problem is attempt.problem
    np.testing.assert_array_equal(again.candidates, attempt.seeds)
    repeated = search(dataclasses.replace(attempt, seeds=again.candidates, number=1), None, None)
    assert repeated.fitness == searched.fitness and repeated.x.tolist() == searched.x.tolist()
    assert PathSeeding().after(attempt, searched) is None


def test_a_time_limit_draws_until_the_limit_rather_than_max_samples(window: Problem) -> None:
    """A path that needs more samples than ``max_samples`` is found when the plan has time left."""
    import time

    from planning.pipeline.deadline import Deadline
    from planning.pipeline.path_seeds import DEADLINE_SAMPLES, draw_samples

    few = with_planner(window, tuning=SearchTuning(seeding=SeedingTuning(max_samples=2, finer_after=1)))
    assert draw_samples(few) == 2 and PathSeeding().first(few).no_path
    timed = dataclasses.replace(few, deadline=Deadline.after(60.0, time.perf_counter()))
    assert draw_samples(timed) == DEADLINE_SAMPLES
    attempt = PathSeeding().first(timed)
    assert not attempt.no_path and attempt.path is not None and attempt.tried == ""
    passed = dataclasses.replace(few, deadline=Deadline.after(1e-9, time.perf_counter()))
    assert PathSeeding().first(passed).path is None  # the limit ends the draw


@pytest.mark.slow
def test_samples_near_the_trees_lead_a_goal_out_of_its_shelf(tmp_path: Any) -> None:
    """MotionBenchMaker's Panda bookshelf_thin_0089 (vamp-planner's problems, from PyPI, cached).

    Its goal reaches between cans on a thin shelf (a third of the configurations 0.1 rad about
    it collide): the goal's tree extended towards uniform samples almost never grows out, and
    RRT-Connect finds no path keeping the clearance in 3,000 samples. Drawing a fifth of the
    samples about the trees' own nodes (the default) finds one within them, for every seed.
    """
    from planning.bench.mbm import import_problem, problems
    from planning.io.scene_file import load_scene
    from planning.pipeline.seeding import lazy_finer_problem
    from planning.search.rrt_settings import RrtSettings

    problem = next(p for p in problems("panda", ("bookshelf_thin",)) if p.index == 89)
    built = build_problem(load_scene(import_problem(problem, tmp_path / "thin_0089.yaml")))
    finer = lazy_finer_problem(built)
    tuning = SeedingTuning()
    settings = RrtSettings(max_samples=3000, resolution_m=0.01, explore_resolution_m=tuning.max_resolution_m)
    for seed in range(3):
        local = sampled_path(built, np.random.default_rng(seed), settings, finer)
        assert local is not None and not local.relaxed  # the margin kept, without the finer step's
        uniform = dataclasses.replace(settings, local_share=0.0)
        assert sampled_path(built, np.random.default_rng(seed), uniform, finer) is None


def test_an_infeasible_path_seed_is_refined_without_the_firefly(robot: ck.Robot) -> None:
    """Pillars whose paths' seeds all cut into the margin: the refinement starts from the best seed.

    With ``explore_path_seed`` the firefly explores first, as it does from the straight line
    alone; both plans pass the certified check.
    """
    from planning.pipeline.planner import solve
    from planning.pipeline.search import explores

    built = build_problem(narrow_scene(np.random.default_rng(3), robot, "pillars"), robot)
    problem = uniform_samples(built, placements=(0.0,))  # the corners' placement: every seed infeasible
    attempt = PathSeeding().first(problem)
    assert attempt.path is not None and not attempt.feasible_seed and attempt.seeds is not None
    tuning = problem.scene.planner.tuning
    assert not explores(attempt, tuning)
    assert explores(attempt, dataclasses.replace(tuning, explore_path_seed=True))
    assert explores(dataclasses.replace(attempt, path=None), tuning)  # the straight line alone
    assert not explores(dataclasses.replace(attempt, feasible_seed=True), tuning)
    assert explores(None, tuning) and explores(dataclasses.replace(attempt, seeds=None), tuning)

    at_once = solve(problem)
    exploring = solve(with_planner(problem, tuning=dataclasses.replace(tuning, explore_path_seed=True)))
    assert at_once.verification.accepted and exploring.verification.accepted
    assert at_once.optimiser.evaluation_history[0] == len(attempt.seeds)  # the seeds, evaluated once
    assert exploring.optimiser.evaluation_history[0] == problem.scene.planner.firefly.fireflies


PANDA_AT_A_POST = {
    "robot": "panda",
    "start": {"q": [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]},
    "goal": {"q": [1.2, 0.2, 0.0, -1.8, 0.0, 2.0, 0.785]},
    "obstacles": [{"name": "post", "shape": "box", "size": [0.1, 0.1, 0.8], "xyz": [0.45, 0.35, 0.4]}],
}


def test_a_robot_with_pairs_of_its_own_grows_rrt_connect_s_trees_on_the_obstacles_alone() -> None:
    """The draw's validity is the whole clearance check; its screen the obstacles' alone, which
    accepts every configuration the check accepts and some the robot's own links refuse."""
    problem = build_problem(parse_scene(PANDA_AT_A_POST))
    valid = clearance_validity(problem)
    assert isinstance(valid, ScreenedValidity)
    objective, world = problem.objective, problem.world
    limits = problem.robot.limits
    moving = problem.moving
    q = np.random.default_rng(42).uniform(limits.lower[moving], limits.upper[moving], (80, moving.size))
    configurations = problem.configurations(q)
    whole = world.keeps_clearance(configurations, objective.required_m, objective.required_self_m)
    obstacles = ~world.margin_violated(configurations, objective.required_m)
    one_by_one = np.array([[valid(row[None])[0], valid.screen(row[None])[0]] for row in q])
    np.testing.assert_array_equal(one_by_one[:, 0], whole)
    np.testing.assert_array_equal(one_by_one[:, 1], obstacles)
    assert (obstacles >= whole).all() and (obstacles > whole).any()  # some the links refuse
    found = sampled_path(problem, np.random.default_rng(0))
    assert found is not None and valid(found.path).all()


def test_a_robot_without_pairs_of_its_own_has_no_screen(window: Problem) -> None:
    assert screen_of(clearance_validity(window)) is None
