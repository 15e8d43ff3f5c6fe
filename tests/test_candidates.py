from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning import build_problem
from planning.bench.arm_scenes import blocked_scene
from planning.bench.scene_generator import generate_scenes
from planning.curves.trajectory import Trajectory
from planning.io.bundled import paper_scene
from planning.io.scene_file import parse_scene
from planning.pipeline import choose as choose_module
from planning.pipeline.choose import Choice, Refusal, beyond_margin, choose, distinct, verify
from planning.pipeline.deadline import Deadline
from planning.pipeline.offered import Offered
from planning.pipeline.planner import solve
from planning.pipeline.problem import Problem
from planning.pipeline.timing import FixedDuration, TimedProblem
from planning.pipeline.tuning import SearchTuning
from planning.pipeline.verification import Verification
from planning.search.optimizer import SearchResult

PREFERRED_FIRST = SearchTuning().preferred_first
NARROWED_ACCELERATION = SearchTuning().narrowed_acceleration


@dataclass(frozen=True)
class CountingDuration(FixedDuration):
    """The paper case's duration rule, recording every path it times."""

    timed: list[np.ndarray] = field(default_factory=list)

    def timings(self, problem: TimedProblem, nodes: np.ndarray) -> Offered:
        self.timed.append(nodes)
        return super().timings(problem, nodes)


def test_distinct_keeps_the_first_of_each_point_in_order() -> None:
    a, b = np.array([0.1, 0.2]), np.array([0.3, 0.4])
    near = np.array([0.1, 0.2 + 1e-12])  # another point, however close
    kept = distinct([a, b, a.copy(), near, b])
    assert [point.tolist() for point in kept] == [a.tolist(), b.tolist(), near.tolist()]
    assert distinct([]) == []


def blocked_then_found(problem: Problem) -> SearchResult:
    """The paper case's straight swing (it hits the crate) twice, then the plan's own best."""
    blocked = problem.objective.straight_line()
    fixed = problem.duration.timings(problem, problem.objective.nodes(blocked[None])[0]).first
    assert not verify(problem, fixed.trajectory, fixed.fit).accepted
    found = solve(problem).optimiser.x
    return SearchResult(
        x=blocked,
        fitness=1.0,
        evaluations=3,
        best_history=np.ones(1),
        mean_history=np.ones(1),
        evaluation_history=np.array([3]),
        population=np.stack([blocked, blocked.copy(), found]),
        population_fitness=np.array([1.0, 1.0, 2.0]),
    )


def test_a_refused_point_is_timed_and_verified_once(robot: ck.Robot) -> None:
    # after a refinement the best is also its population's first: refused once, it is not
    # timed and verified again before the next distinct candidate
    problem = build_problem(paper_scene(0), robot)
    result = blocked_then_found(problem)
    counting = CountingDuration(4.0)  # the paper case's duration
    counted = replace(problem, duration=counting)
    chosen = choose(counted, result, beyond_margin(counted, result))
    assert isinstance(chosen, Choice)
    np.testing.assert_array_equal(chosen.x, result.population[2])
    assert chosen.verification.accepted
    assert chosen.candidates_timed == len(counting.timed) == 2


def test_past_the_deadline_only_the_timing_in_hand_is_verified(robot: ck.Robot) -> None:
    # the same candidates, time up: the best's timing is verified, refused, and nothing more tried
    problem = build_problem(paper_scene(0), robot)
    result = blocked_then_found(problem)
    counting = CountingDuration(4.0)
    late = replace(problem, duration=counting, deadline=Deadline(0.0, 1.0))
    chosen = choose(late, result, beyond_margin(late, result))
    assert isinstance(chosen, Refusal) and chosen.verified == "1 candidate verified"
    assert len(counting.timed) == 1
    in_time = choose(replace(late, deadline=Deadline()), result, beyond_margin(late, result))
    assert isinstance(in_time, Choice)  # the oracle: a later candidate passes


def test_once_the_best_is_refused_the_next_candidates_run_at_full_speed_before_any_narrowed_timing(
    robot: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the refinement's population is nearly as good as its best: the next one at full speed,
    # timed only once the best failed; the narrowed timings only once those fail, shortest first.
    # The order without the foresight (tested in test_averaged_path.py), on the first generated
    # scene (of seed 0, from 30 on) whose second candidate's fastest timing passes (the oracle)
    monkeypatch.setattr(choose_module, "foreseen_clear", lambda _, x: np.ones(len(x), dtype=bool))
    for scene in generate_scenes(40, 0, robot)[30:]:
        problem = build_problem(scene, robot)
        searched = solve(problem).optimiser
        order = np.argsort(searched.population_fitness, kind="stable")
        points = distinct([searched.x] + [searched.population[k] for k in order])[:PREFERRED_FIRST]
        offered = [problem.duration.timings(problem, problem.objective.nodes(x[None])[0]) for x in points]
        fastest = [timing.first for timing in offered]
        if len(points) == PREFERRED_FIRST and verify(problem, fastest[1].trajectory, fastest[1].fit).accepted:
            break
    else:
        pytest.fail("no scene of seed 0 from 30 to 39 whose second candidate passes at full speed")
    result = replace(
        searched,
        population=np.stack(points),
        population_fitness=np.arange(1.0, len(points) + 1),
    )
    refused = {fastest[0].trajectory.duration}

    def refusing(problem_: object, trajectory: Trajectory, fit: object) -> Verification:
        checked = verify(problem, trajectory, fit)  # type: ignore[arg-type]
        if trajectory.duration in refused:
            return Verification(checked.check, ("refused by the test",))
        return checked

    monkeypatch.setattr(choose_module, "verify", refusing)
    chosen = choose(problem, result, beyond_margin(problem, result))
    assert isinstance(chosen, Choice) and chosen.candidates_timed == 2  # the third not timed
    assert chosen.timing.trajectory.duration == fastest[1].trajectory.duration

    refused.update(timing.trajectory.duration for timing in fastest)  # every full-speed timing
    narrowed = [problem.duration.narrowed(problem, timing, NARROWED_ACCELERATION[0]) for timing in offered]
    passing = [
        t.trajectory.duration
        for t in narrowed
        if t is not None and verify(problem, t.trajectory, t.fit).accepted
    ]
    assert passing
    chosen = choose(problem, result, beyond_margin(problem, result))
    assert isinstance(chosen, Choice) and chosen.timing.method == "narrowed"
    assert chosen.timing.trajectory.duration == min(passing)


def test_a_refusal_for_the_robots_own_links_names_them_not_an_obstacle() -> None:
    # a UR10 whose straight swing folds its wrist onto its forearm, the ball far away: the
    # message once named the closest obstacle pair (1.06 m, clear) beside a mean depth of 1e-7 m;
    # on the links' hulls alone (the wrist's exact mesh clears the forearm's on this swing)
    ur10 = replace(ck.load_robot(example_robot("ur10")), exact_meshes={})
    document = blocked_scene("ur10_523", "ur10", ur10, 523, self_clearance_m=0.015)
    # its goal pose reached with wrist_1 a turn from the start's nearest (the IK now takes that
    # one, whose swing folds nothing): the straight swing of 5.7 rad then folds the wrist
    document["goal"] = {"q": [2.79753, -3.110798, -1.008705, 3.705861, 0.944859, -5.020057]}
    problem = build_problem(parse_scene(document), ur10)
    straight = problem.objective.straight_line()
    fitness = float(problem.objective(straight[None])[0])
    assert not problem.objective.feasible(fitness)
    alone = SearchResult.of_point(straight, fitness, 1)
    chosen = choose(problem, alone, beyond_margin(problem, alone))
    assert isinstance(chosen, Refusal)
    assert chosen.cause.startswith("no candidate was feasible; the best comes within -")
    assert "(certified) of itself, forearm_link to wrist_" in chosen.cause and "ball" not in chosen.cause


def test_a_refusal_off_the_obstacles_keeps_the_fixed_durations_advice(robot: ck.Robot) -> None:
    # no obstacle: the check's words name the nodes, not the fixed duration's limits, which a
    # detour of the first joint exceeds in 1.2 s
    problem = build_problem(replace(paper_scene(0), duration=1.2, obstacles=()), robot)
    waypoints = problem.objective.straight_line().reshape(problem.scene.planner.waypoints, -1)
    waypoints[:, 0] += 0.4  # theta1 [rad]
    detour = waypoints.ravel()
    fitness = float(problem.objective(detour[None])[0])
    assert problem.objective.breakdown(detour[None]).limit_excess[0] > 0
    alone = SearchResult.of_point(detour, fitness, 1)
    chosen = choose(problem, alone, beyond_margin(problem, alone))
    assert isinstance(chosen, Refusal)
    assert chosen.cause.startswith("no candidate was feasible: limits exceeded by ")
    assert "in 1.2 s (lengthen duration or leave it out); the best " in chosen.cause
