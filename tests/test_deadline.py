"""The planner's time limit (:mod:`planning.pipeline.deadline`): each stage stops where it passes."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import cpr_kin as ck
import planning.pipeline.deadline as deadline_module
from cpr_kin.model.packages import example_robot
from planning.cli.app import main
from planning.errors import NoTrajectoryFoundError, PlanningError
from planning.io.bundled import paper_scene
from planning.io.scene_file import parse_scene
from planning.pipeline import planner
from planning.pipeline.choose import Choice, Refusal, beyond_margin, choose
from planning.pipeline.deadline import MIN_OVERRUN_S, Deadline, overrun_s
from planning.pipeline.hulls_first import HULLS_SHARE
from planning.pipeline.path_following import follow_path
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.search import search
from planning.pipeline.seeding import SEEDINGS, Attempt
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.verification import STOPPED
from planning.search.firefly import firefly_minimize
from planning.search.firefly_settings import FireflySettings
from planning.search.refinement import cma_refine
from planning.search.rrt_connect import rrt_connect

from .conftest import after_calls
from .test_hull_first import BALL, CLEAR_ON_HULLS, ur10_scene
from .test_path_following import spline_touching_scene
from .test_rrt_connect import LOWER, UPPER, WEIGHTS, wall_with_slot


def sphere(x: np.ndarray) -> np.ndarray:
    return np.asarray(np.sum((x - 0.3) ** 2, axis=1))


def test_a_deadline_passes_at_its_limit() -> None:
    now = time.perf_counter()
    assert not Deadline().passed()
    assert Deadline.after(None, now) == Deadline()
    assert Deadline.after(1e-9, now - 1.0).passed()
    assert not Deadline.after(3600.0, now).passed()
    assert "after 2.1 s by the time limit time_limit_s = 2 s" in Deadline.after(2.0, now - 2.1).reason()


def test_time_numba_spends_compiling_is_not_counted(monkeypatch: pytest.MonkeyPatch) -> None:
    compiling_s = [100.0]  # what the process compiled before the plan began
    monkeypatch.setattr(deadline_module, "compile_seconds", lambda: compiling_s[0])
    now = time.perf_counter()
    two = Deadline.after(2.0, now - 3.0)  # three seconds ago, none of them compiling
    assert two.passed() and two.cut()  # 3 s > 2 s + the 1 s overrun
    assert "after 3 s by the time limit" in two.reason()
    compiling_s[0] += 1.5  # then a kernel compiled for 1.5 s: 1.5 s of the plan's own
    assert not two.passed() and not two.cut()
    compiling_s[0] -= 1.0  # 0.5 s of it: 2.5 s of the plan's own
    assert two.passed() and not two.cut()
    assert "after 2.5 s by the time limit" in two.reason()


def test_a_check_under_way_is_cut_an_overrun_after_the_limit() -> None:
    now = time.perf_counter()
    assert overrun_s(10.0) == 2.5 and overrun_s(2.0) == MIN_OVERRUN_S == 1.0  # a quarter, at least 1 s
    ten = Deadline.after(10.0, now)
    assert ten.cut_at_s - ten.at_s == pytest.approx(2.5) and not ten.cut() and ten.stop == ten.cut
    assert Deadline().stop is None and Deadline(0.0, 1.0).stop is None  # nothing cut: no question asked
    assert Deadline(0.0, 1.0, 0.0).cut()


def test_past_the_cut_the_check_under_way_stops_and_its_candidate_is_refused(robot: ck.Robot) -> None:
    problem = build_problem(paper_scene(), robot)
    searched = search(Attempt(problem), None, None)
    deepest = beyond_margin(problem, searched)
    late = choose(dataclasses.replace(problem, deadline=Deadline(0.0, 1.0)), searched, deepest)
    assert isinstance(late, Choice)  # the oracle: past the limit, before the cut, the best passes
    cut = choose(dataclasses.replace(problem, deadline=Deadline(0.0, 1.0, 0.0)), searched, deepest)
    assert isinstance(cut, Refusal) and cut.verified == "1 candidate verified"
    assert cut.cause == f"the best candidate {STOPPED}" and not cut.check.times.size
    message = str(cut.error())
    assert "its check was stopped by the time limit before its verdict" in message


def test_only_a_plan_with_a_limit_gives_its_checks_a_stop(
    robot: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    import planning.pipeline.choose as choosing
    from planning.pipeline.verification import verify_trajectory as original

    stops: list[Any] = []

    def recorded(*args: Any, stop: Any = None) -> Any:
        stops.append(stop)
        return original(*args, stop=stop)

    monkeypatch.setattr(choosing, "verify_trajectory", recorded)
    plan(paper_scene(), robot)
    assert stops and all(stop is None for stop in stops)  # nothing asked, nothing cut in pieces
    stops.clear()
    plan(limited(paper_scene(), 3600.0), robot)
    assert stops and all(callable(stop) and not stop() for stop in stops)


def test_the_hulls_share_of_a_limit_is_cut_where_the_plan_is(monkeypatch: pytest.MonkeyPatch) -> None:
    ur10 = ck.load_robot(example_robot("ur10"))
    scene = parse_scene({**ur10_scene(CLEAR_ON_HULLS), "obstacles": [BALL]}).with_planner(time_limit_s=600.0)
    deadlines: list[tuple[Deadline, Deadline]] = []

    def recorded(problem: Any, deadline: Deadline, *args: Any) -> Any:
        deadlines.append((deadline, args[-1]))
        return solved(problem, deadline, *args)

    solved = planner._solved
    monkeypatch.setattr(planner, "_solved", recorded)
    plan(scene, ur10)
    hulls, whole = deadlines[0]
    assert hulls.limit_s == 600.0 * HULLS_SHARE and whole.limit_s == 600.0
    assert hulls.at_s < whole.at_s and hulls.cut_at_s == whole.cut_at_s == whole.at_s + 150.0
    assert hulls.feasible_at_s == whole.at_s and whole.feasible_at_s is None  # a feasible search's end


def test_a_deadline_for_a_search_holding_a_feasible_candidate() -> None:
    share = Deadline(0.0, 1.0, feasible_at_s=np.inf)  # a share passed; the plan's own deadline never
    assert share.passed() and not share.passed(feasible=True)
    assert Deadline(0.0, 1.0).passed(feasible=True)  # no share: the same deadline either way
    assert Deadline(np.inf, 1.0, feasible_at_s=0.0).passed(feasible=True)


def test_a_share_past_its_end_stops_only_a_search_that_found_nothing_feasible(robot: ck.Robot) -> None:
    """Past the hulls' share of a limit, a search whose objective has seen a feasible candidate
    refines it on to the plan's own deadline; one that has not stops after its first batch."""
    scene = dataclasses.replace(paper_scene(), planner=PlannerSettings(seed=3))
    problem = build_problem(scene, robot)
    attempt = SEEDINGS[scene.planner.seeding].first(problem)
    assert attempt.feasible_seed  # the oracle: the search holds a feasible candidate from its seeds

    def searched(deadline: Deadline) -> int:
        late = dataclasses.replace(attempt, problem=dataclasses.replace(problem, deadline=deadline))
        return search(late, None, None).evaluations

    seeds = len(attempt.seeds) if attempt.seeds is not None else 0
    assert searched(Deadline(0.0, 1.0)) == seeds  # time up: the seeds evaluated, nothing refined
    assert searched(Deadline(0.0, 1.0, feasible_at_s=np.inf)) > seeds  # the share passed: refined on


def test_rrt_connect_stops_without_a_path() -> None:
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    args = (wall_with_slot, start, goal, LOWER, UPPER, WEIGHTS)
    assert rrt_connect(*args, np.random.default_rng(0)) is not None  # the oracle: it finds the slot
    calls, stop = after_calls(3)
    assert rrt_connect(*args, np.random.default_rng(0), stop=stop) is None
    assert len(calls) == 4  # asked before each sample: three drawn, the fourth not


def test_the_searches_stop_with_their_best_so_far() -> None:
    settings = FireflySettings(fireflies=10, iterations=50, stall_iterations=0)
    bounds = (np.zeros(3), np.ones(3))
    full = firefly_minimize(sphere, *bounds, settings, 1)
    _, stop = after_calls(2)
    cut = firefly_minimize(sphere, *bounds, settings, 1, stop=stop)
    assert cut.evaluations == 3 * 10  # the initial population and two iterations
    np.testing.assert_array_equal(cut.best_history, full.best_history[:3])  # the same run, cut short
    start = np.full(3, 0.8)
    value = float(sphere(start[None])[0])
    _, never = after_calls(10**9)
    refined = cma_refine(sphere, *bounds, start, value, 500, np.random.default_rng(2), stop=never)
    _, at_once = after_calls(0)
    kept = cma_refine(sphere, *bounds, start, value, 500, np.random.default_rng(2), stop=at_once)
    assert refined.evaluations > 0 and refined.fitness < value
    assert kept.evaluations == 0 and kept.fitness == value
    np.testing.assert_array_equal(kept.x, start)


def limited(scene: Scene, limit_s: float | None) -> Scene:
    return scene.with_planner(time_limit_s=limit_s)


def test_a_plan_stopped_by_its_limit_says_so(robot: ck.Robot) -> None:
    scene = limited(paper_scene(), 1e-9)  # the crate blocks the straight line: a search is needed
    with pytest.raises(NoTrajectoryFoundError, match=r"by the time limit time_limit_s = 1e-09 s \(raise it"):
        plan(scene, robot)


def test_a_plan_within_its_limit_is_the_plan_without(robot: ck.Robot) -> None:
    free = plan(paper_scene(), robot)
    within = plan(limited(paper_scene(), 3600.0), robot)
    np.testing.assert_array_equal(within.trajectory.coefficients, free.trajectory.coefficients)


def test_a_plan_cut_short_returns_what_it_verified(robot: ck.Robot) -> None:
    # nothing in the way: the straight line, the first seed, is verified and returned
    scene = limited(dataclasses.replace(paper_scene(), obstacles=()), 1e-9)
    result = plan(scene, robot)
    assert result.verification.accepted
    assert result.optimiser.evaluations <= scene.planner.firefly.fireflies  # no iteration after the seeds


def test_past_the_limit_the_last_resort_is_not_run(robot: ck.Robot, monkeypatch: pytest.MonkeyPatch) -> None:
    """A scene only the last resort plans (its path followed through its vertices): once time is up
    after the search's choice, the plan stops there, saying that a path was found."""
    scene = spline_touching_scene(robot).with_planner(refine="none", time_limit_s=3600.0)
    assert plan(scene, robot).metrics.timing == "through_path"  # within the limit: the last resort
    chosen: list[int] = []
    followed: list[int] = []

    class SpentAfterTheChoice(Deadline):
        def passed(self, feasible: bool = False) -> bool:
            return bool(chosen)

    def counted(calls: list[int], function: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any) -> Any:
            calls.append(1)
            return function(*args)

        return call

    monkeypatch.setattr(planner, "Deadline", SpentAfterTheChoice)
    monkeypatch.setattr(planner, "choose", counted(chosen, choose))
    monkeypatch.setattr(planner, "follow_path", counted(followed, follow_path))
    found = r"RRT-Connect found a path, but the time limit passed before it was followed"
    with pytest.raises(NoTrajectoryFoundError, match=found) as error:
        plan(scene, robot)
    assert "by the time limit time_limit_s = 3600 s" in str(error.value)
    assert chosen == [1] and not followed


def test_a_callers_optimizer_is_stopped_through_its_objective(robot: ck.Robot) -> None:
    """A caller's optimiser knows no deadline: past it, its objective's next call ends its run
    (even through its own ``except Exception``), and the search returns the best it saw."""
    problem = dataclasses.replace(build_problem(paper_scene(), robot), deadline=Deadline(0.0, 1.0))
    batches: list[tuple[np.ndarray, np.ndarray]] = []

    def endless(objective: Any, lower: np.ndarray, upper: np.ndarray, budget: int, rng: Any) -> Any:
        for _ in range(50):  # a budget of its own, never reached while time is up
            x = rng.uniform(lower, upper, (4, lower.size))
            try:
                batches.append((x, objective(x)))
            except Exception:  # an optimiser that swallows its objective's errors
                continue
        raise AssertionError("the deadline did not stop it")

    searched = search(Attempt(problem), None, endless)
    ((x, values),) = batches  # the first batch only: time was up before it
    assert searched.evaluations == 4 and searched.fitness == values.min()
    np.testing.assert_array_equal(searched.x, x[np.argmin(values)])
    free = dataclasses.replace(problem, deadline=Deadline())  # without a deadline it runs to its end
    with pytest.raises(AssertionError, match="did not stop"):
        search(Attempt(free), None, endless)


def test_the_limit_is_validated() -> None:
    with pytest.raises(PlanningError, match=r"time_limit_s = 0.0 s must be a number in \(0, 86400\] s"):
        PlannerSettings(time_limit_s=0.0)


def test_the_command_line_limit(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "out"
    code = main(["paper", "--out", str(out), "--time-limit", "1e-9"])
    stderr = capsys.readouterr().err
    assert code == 3 and "time limit time_limit_s = 1e-09 s" in stderr and "Traceback" not in stderr
    assert not out.exists()
