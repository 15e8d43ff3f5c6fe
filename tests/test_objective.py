from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.io.bundled import paper_scene
from planning.pipeline.motion import Motion
from planning.pipeline.objective import PathRules, WaypointObjective
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.timing import FixedDuration


def make_objective(
    robot: ck.Robot,
    obstacles: list[ck.Obstacle],
    q_start: np.ndarray,
    q_goal: np.ndarray,
    **overrides: object,
) -> WaypointObjective:
    scene = paper_scene()
    settings = PlannerSettings(**{**scene.planner.__dict__, **overrides})
    solver = SepticSplineSolver(uniform_knots(settings.waypoints + 1, 4.0), scene.spline)
    world = ck.CollisionWorld(robot, obstacles)
    motion = Motion(q_start, q_goal, np.array([0, 1, 2]))
    return WaypointObjective(world, motion, PathRules(0.1, 0.01), settings, solver, FixedDuration(4.0))


@pytest.fixture(scope="module")
def paper_objective(robot: ck.Robot, crate: ck.Obstacle) -> WaypointObjective:
    scene = paper_scene()
    return make_objective(robot, [crate], scene.start.configuration(robot), scene.goal.configuration(robot))


def test_longest_solution(paper_objective: WaypointObjective) -> None:
    # theta1 is the slowest over its full range: 5.8 / 1.5 + 1.5 / 3; four segments; plus one IPO
    assert paper_objective.t_max == pytest.approx(4 * (5.8 / 1.5 + 1.5 / 3.0) + 0.012)
    assert paper_objective.w_max == 12.0
    assert paper_objective.dimension == 9


def test_nodes_hold_the_wrist(paper_objective: WaypointObjective, rng: np.random.Generator) -> None:
    x = rng.uniform(paper_objective.lower, paper_objective.upper, (4, 9))
    nodes = paper_objective.nodes(x)
    assert nodes.shape == (4, 5, 5)
    np.testing.assert_array_equal(nodes[:, 1:-1, :3], x.reshape(4, 3, 3))
    np.testing.assert_array_equal(nodes[:, :, 3:], 0.0)
    np.testing.assert_array_equal(nodes[:, 0], np.tile(paper_objective.q_start, (4, 1)))


@pytest.mark.parametrize("fitness", ["clearance", "paper"])
def test_every_feasible_candidate_ranks_ahead_of_every_infeasible_one(
    robot: ck.Robot, crate: ck.Obstacle, rng: np.random.Generator, fitness: str
) -> None:
    scene = paper_scene()
    objective = make_objective(
        robot, [crate], scene.start.configuration(robot), scene.goal.configuration(robot), fitness=fitness
    )
    # waypoints near a lift-over detour: a mix of feasible and infeasible candidates
    lift = np.concatenate(
        [ck.tcp_ik(robot, p)[:3] for p in ((0.4, 0.5, 0.6), (0.0, 0.7, 0.7), (-0.4, 0.5, 0.6))]
    )
    x = np.clip(lift + rng.normal(scale=0.04, size=(200, 9)), objective.lower, objective.upper)
    b = objective.breakdown(x)
    assert 10 < b.feasible.sum() < 190
    assert b.fitness[b.feasible].max() < b.fitness[~b.feasible].min()
    assert np.all(b.fitness[b.feasible] <= objective.t_max)
    # the one rule: a fitness says whether its candidate is feasible
    np.testing.assert_array_equal(objective.feasible(b.fitness), b.feasible)
    np.testing.assert_allclose(
        b.fitness[b.feasible], (b.t_sol_s + b.w_sol / objective.w_max * 0.012)[b.feasible]
    )


def test_paper_branches_follow_the_colliding_group(robot: ck.Robot, crate: ck.Obstacle) -> None:
    # effector only: the tool skims 0.05 m above the crate, the arm beam 0.175 m
    start, goal = ck.tcp_ik(robot, (0.5, 0.45, 0.35)), ck.tcp_ik(robot, (-0.5, 0.45, 0.35))
    over = np.concatenate(
        [ck.tcp_ik(robot, p)[:3] for p in ((0.2, 0.6, 0.35), (0.0, 0.6, 0.35), (-0.2, 0.6, 0.35))]
    )
    objective = make_objective(robot, [crate], start, goal, fitness="paper", path="ptp")
    b = objective.breakdown(over[None])
    assert b.effector_violates[0] and not b.links_violate[0]
    base = b.t_sol_s[0] + b.w_sol[0] / objective.w_max * 0.012
    assert b.fitness[0] == pytest.approx(2 * objective.t_max - base)  # eq. 5

    # links only: the retracted arm's rear end sweeps through a block behind the column
    block = ck.Obstacle.box((0.1, 0.1, 0.1), (-0.45, 0.0, 0.55), name="block")
    start, goal = np.array([-0.3, 0.3, 0.0, 0, 0]), np.array([0.3, 0.3, 0.0, 0, 0])
    through = np.tile([0.0, 0.3, 0.0], 3)
    objective = make_objective(robot, [block], start, goal, fitness="paper", path="ptp")
    b = objective.breakdown(through[None])
    assert b.links_violate[0] and not b.effector_violates[0]
    base = b.t_sol_s[0] + b.w_sol[0] / objective.w_max * 0.012
    assert b.fitness[0] == pytest.approx(2 * objective.t_max + base)  # eq. 6, our reading


def test_clearance_fitness_grows_with_violation_depth(robot: ck.Robot, crate: ck.Obstacle) -> None:
    start, goal = ck.tcp_ik(robot, (0.5, 0.45, 0.5)), ck.tcp_ik(robot, (-0.5, 0.45, 0.5))
    objective = make_objective(robot, [crate], start, goal, path="ptp")
    heights = (0.5, 0.38, 0.34, 0.31)  # tool tip 0.2, 0.08, 0.04, 0.01 m above the crate
    rows = [np.concatenate([ck.tcp_ik(robot, (x, 0.6, z))[:3] for x in (0.2, 0.0, -0.2)]) for z in heights]
    b = objective.breakdown(np.array(rows))
    assert b.feasible[0] and not b.feasible[1:].any()
    assert np.all(np.diff(b.depth_m[1:]) > 0)
    assert np.all(np.diff(b.fitness[1:]) > 0)


def test_w_sol_of_the_spline_is_at_least_the_ptp_one(
    paper_objective: WaypointObjective, rng: np.random.Generator
) -> None:
    x = rng.uniform(paper_objective.lower, paper_objective.upper, (20, 9))
    nodes = paper_objective.nodes(x)
    ptp = (np.abs(np.diff(nodes, axis=1)) / paper_objective.paths.range_q).sum(axis=(1, 2))
    spline = paper_objective.breakdown(x).w_sol
    assert np.all(spline >= ptp - 1e-6)


@pytest.mark.parametrize("theta4_goal", [0.0, 0.6])  # held; not a waypoint joint, yet it moves
def test_limit_excess_and_w_sol_match_the_fitted_trajectories(
    robot: ck.Robot, crate: ck.Obstacle, rng: np.random.Generator, theta4_goal: float
) -> None:
    from planning.curves.spline import fit_septic_spline

    scene = paper_scene()
    q_goal = scene.goal.configuration(robot)
    q_goal[3] = theta4_goal
    objective = make_objective(robot, [crate], scene.start.configuration(robot), q_goal)
    centre = np.tile((objective.q_start[:3] + objective.q_goal[:3]) / 2, 3)
    spread = rng.normal(0.0, 0.08, (40, 9)) * (objective.upper - objective.lower)
    x = np.clip(centre + spread, objective.lower, objective.upper)
    breakdown = objective.breakdown(x)
    limits = objective.world.robot.limits
    knots = objective.solver.knots
    ipo_times = np.append(np.arange(knots[0], knots[-1], objective.settings.ipo), knots[-1])
    for candidate, nodes in enumerate(objective.nodes(x)):
        trajectory = fit_septic_spline(knots, nodes, paper_scene().spline).trajectory
        utilisation = max(
            float((np.abs(trajectory(ipo_times, r)).max(axis=0) / limit).max())
            for r, limit in ((1, limits.velocity), (2, limits.acceleration), (3, limits.jerk))
        )
        assert breakdown.limit_excess[candidate] == pytest.approx(max(utilisation - 1.0, 0.0), abs=1e-9)
        w_sol = (np.abs(np.diff(trajectory(ipo_times), axis=0)) / limits.range).sum()
        assert breakdown.w_sol[candidate] == pytest.approx(w_sol, rel=1e-9)
        deviation = np.abs(trajectory(knots) - nodes).max()
        assert breakdown.node_deviation[candidate] == pytest.approx(deviation, rel=1e-6, abs=1e-12)
    assert (breakdown.limit_excess == 0).any() and (breakdown.limit_excess > 0).any()


def test_lower_bound_of_the_ptp_time_is_the_direct_move(
    paper_objective: WaypointObjective, rng: np.random.Generator
) -> None:
    # the slowest joint's trapezoid (or triangle) time from start to goal, written out
    limits = paper_objective.world.robot.limits
    distance = np.abs(paper_objective.q_goal - paper_objective.q_start)
    v, a = limits.velocity, limits.acceleration
    cruise = distance >= v**2 / a
    times = np.where(cruise, distance / v + v / a, 2 * np.sqrt(distance / a))
    assert paper_objective.lower_bound == pytest.approx(times.max(), rel=1e-12)
    # stopping at waypoints never takes less: the trapezoid time is subadditive
    x = rng.uniform(paper_objective.lower, paper_objective.upper, (500, 9))
    assert paper_objective.breakdown(x).t_sol_s.min() >= paper_objective.lower_bound


def test_lower_bound_of_the_duration_estimate_is_the_straight_lines(robot: ck.Robot) -> None:
    from planning.bench.ruckig_bound import free_space_bound
    from planning.pipeline.problem import build_problem

    problem = build_problem(dataclasses.replace(paper_scene(), duration=None, obstacles=()), robot)
    objective = problem.objective
    assert objective.estimates_duration
    # with no obstacle the straight line is feasible: the bound is its estimate
    straight = objective.breakdown(objective.straight_line()[None])
    assert straight.feasible[0]
    assert objective.lower_bound == pytest.approx(float(straight.duration_s[0]), rel=1e-12)
    # within a few percent above Ruckig's time-optimal jerk-limited motion (no path is faster)
    assert 1.0 <= objective.lower_bound / free_space_bound(problem) <= 1.1
