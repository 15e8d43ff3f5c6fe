from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import cpr_kin as ck
from planning import build_problem
from planning import candidates as candidates_module
from planning.candidates import PREFERRED_FIRST, distinct, first_verified, verify
from planning.curves.trajectory import Trajectory
from planning.io.bundled import paper_scene
from planning.io.scene_generator import generate_scenes
from planning.planner import solve
from planning.search.optimizer import SearchResult
from planning.timing import NARROWED_ACCELERATION, Timing, narrowed_timing, timings
from planning.verification import Verification


def test_distinct_keeps_the_first_of_each_point_in_order() -> None:
    a, b = np.array([0.1, 0.2]), np.array([0.3, 0.4])
    near = np.array([0.1, 0.2 + 1e-12])  # another point, however close
    kept = distinct([a, b, a.copy(), near, b])
    assert [point.tolist() for point in kept] == [a.tolist(), b.tolist(), near.tolist()]
    assert distinct([]) == []


def test_a_refused_point_is_timed_and_verified_once(robot: ck.Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    # after a refinement the best is also its population's first: refused once, it is not
    # timed and verified again before the next distinct candidate
    problem = build_problem(paper_scene(0), robot)
    blocked = problem.objective.straight_line()  # the paper case's straight swing hits the crate
    fixed = timings(problem, problem.objective.nodes(blocked[None])[0])[0]
    assert not verify(problem, fixed.trajectory, fixed.fit).accepted
    found = solve(problem).optimiser.x
    result = SearchResult(
        x=blocked,
        fitness=1.0,
        evaluations=3,
        best_history=np.ones(1),
        mean_history=np.ones(1),
        evaluation_history=np.array([3]),
        population=np.stack([blocked, blocked.copy(), found]),
        population_fitness=np.array([1.0, 1.0, 2.0]),
    )
    timed: list[np.ndarray] = []

    def counting(problem_: object, nodes: np.ndarray) -> list:  # type: ignore[type-arg]
        timed.append(nodes)
        return timings(problem, nodes)

    monkeypatch.setattr(candidates_module, "timings", counting)
    x, _, _, verification, tried = first_verified(problem, result)
    np.testing.assert_array_equal(x, found)
    assert verification.accepted
    assert tried == len(timed) == 2


def test_once_the_best_is_refused_the_shortest_passing_timing_wins(
    robot: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    # a worse candidate at full speed competes with the narrowed timings by duration, not by rank
    problem = build_problem(generate_scenes(31, 0, robot)[30], robot)
    searched = solve(problem).optimiser
    order = np.argsort(searched.population_fitness, kind="stable")
    points = distinct([searched.x] + [searched.population[k] for k in order])[:PREFERRED_FIRST]
    result = replace(
        searched,
        population=np.stack(points),
        population_fitness=np.arange(1.0, len(points) + 1),
    )
    offered = [timings(problem, problem.objective.nodes(x[None])[0]) for x in points]
    refused = offered[0][0].trajectory.duration  # the best's fastest timing

    def refusing(problem_: object, trajectory: Trajectory, fit: object) -> Verification:
        checked = verify(problem, trajectory, fit)  # type: ignore[arg-type]
        if trajectory.duration == refused:
            return Verification(checked.check, ("refused by the test",))
        return checked

    options: list[Timing | None] = [timing[0] for timing in offered[1:]]
    options += [narrowed_timing(problem, timing, NARROWED_ACCELERATION[0]) for timing in offered]
    passing = [
        t.trajectory.duration
        for t in options
        if t is not None and verify(problem, t.trajectory, t.fit).accepted
    ]
    assert passing
    monkeypatch.setattr(candidates_module, "verify", refusing)
    _, _, timing, verification, _ = first_verified(problem, result)
    assert verification.accepted
    assert timing.trajectory.duration == min(passing)
