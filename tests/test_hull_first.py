"""A robot with exact meshes plans on its hulls first, and on the meshes where only they clear the ends."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.certified.motion import motion_radii
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.model.packages import example_robot
from planning import build_problem, plan
from planning.cli import main
from planning.io.scene_file import parse_scene
from planning.pipeline import path_seeds, planner
from planning.pipeline import verification as verification_module
from planning.pipeline.hulls_first import HULLS_SHARE, finer_steps_m, on_hulls
from planning.pipeline.problem import finer_step_m
from planning.pipeline.verification import Requirements, verify_finer_where_needed, verify_for_scene
from planning.search.rrt_connect import rrt_connect
from planning.search.rrt_trees import GrownTrees

# UR10 configurations (self margin 10 mm): its hulls clear, and only its exact meshes clear
CLEAR_ON_HULLS = [-1.57, 2.81, -0.98, -2.02, -0.94, -1.69]
CLEAR_ON_MESHES = [2.5, 0.0, -0.16, 1.17, 0.73, -0.4]
GOAL = [-2.47, -1.52, -0.26, -0.29, -0.2, 2.69]
BALL = {"name": "ball", "shape": "sphere", "radius": 0.4, "xyz": [-0.3, -1.0, -0.3]}
"""Across the way from CLEAR_ON_HULLS to GOAL: RRT-Connect needs a few hundred samples."""


@pytest.fixture(scope="module")
def ur10() -> ck.Robot:
    return ck.load_robot(example_robot("ur10"))


def ur10_scene(start: list[float]) -> dict[str, object]:
    return {"robot": "ur10", "start": {"q": start}, "goal": {"q": GOAL}, "self_margin": 0.01, "obstacles": []}


def test_the_hulls_view_answers_as_a_robot_without_meshes(ur10: ck.Robot) -> None:
    world = ck.CollisionWorld(ur10, [ck.Obstacle.box((0.3, 0.3, 0.3), (0.6, 0.0, 0.4))], self_margin_m=0.01)
    view = world.on_hulls()
    q = np.random.default_rng(7).uniform(ur10.limits.lower / 2, ur10.limits.upper / 2, (300, ur10.nq))
    alone = ck.CollisionWorld(dataclasses.replace(ur10, exact_meshes={}), world.obstacles, self_margin_m=0.01)
    np.testing.assert_array_equal(
        view.self_collision.violated(q, 0.01), alone.self_collision.violated(q, 0.01)
    )
    np.testing.assert_array_equal(view.margin_violated(q, 0.02), alone.margin_violated(q, 0.02))
    np.testing.assert_allclose(view.min_clearance_batch(q)[0], alone.min_clearance_batch(q)[0], atol=1e-9)
    # the world itself still asks its meshes: fewer configurations refused
    assert world.self_collision.violated(q, 0.01).sum() < view.self_collision.violated(q, 0.01).sum()
    assert view.robot.exact_meshes == {} and world.robot.exact_meshes


def test_a_robot_on_its_hulls_is_one_robot_whose_reach_is_computed_once(
    ur10: ck.Robot, robot: ck.Robot
) -> None:
    hulls = ur10.on_hulls
    assert hulls is ur10.on_hulls and hulls.exact_meshes == {} and ur10.exact_meshes
    assert hulls.model is ur10.model and hulls.collision_model is ur10.collision_model
    assert robot.on_hulls is robot  # the CPR has no exact meshes
    world = ck.CollisionWorld(ur10, [], self_margin_m=0.01)
    assert world.on_hulls().robot is hulls and world.on_hulls().robot is hulls  # every plan's view: one robot
    # what is computed once per robot (the reach, the motion radii of every verification) stays computed
    assert robot_reach(hulls) is robot_reach(world.on_hulls().robot)
    np.testing.assert_array_equal(motion_radii(hulls), motion_radii(ur10))  # the same shapes, the same reach


def test_ends_clear_on_the_hulls_plan_there_and_pass_on_the_meshes(ur10: ck.Robot) -> None:
    scene = parse_scene(ur10_scene(CLEAR_ON_HULLS))
    problem = build_problem(scene, ur10)
    assert on_hulls(problem) is not None
    result = plan(scene, ur10)
    assert result.problem.robot.exact_meshes == {}  # planned on the hulls
    assert not verify_for_scene(build_problem(scene, ur10), result.trajectory).problems  # `check`: the meshes


def test_ends_only_the_meshes_clear_plan_on_the_meshes(ur10: ck.Robot) -> None:
    scene = parse_scene(ur10_scene(CLEAR_ON_MESHES))
    problem = build_problem(scene, ur10)  # the hulls alone would refuse its start
    assert on_hulls(problem) is None
    result = plan(scene, ur10)
    assert result.problem.robot.exact_meshes
    assert not verify_for_scene(build_problem(scene, ur10), result.trajectory).problems


def test_ends_within_the_finest_step_of_a_margin_on_the_hulls_plan_on_the_meshes(ur10: ck.Robot) -> None:
    """The fitness requires every sample, the ends too, to keep the margins plus a step of at
    least ``VERIFY_STEP_RANGE_M[0]``: ends nearer on the hulls leave their search nothing
    feasible (seen on the G1's arm: three searches to their budget, 1.5 s each, on hulls
    whose ends sat 0.03 mm beyond the self margin); a margin set just beyond that plans on
    the hulls as before."""
    from planning.pipeline.settings import VERIFY_STEP_RANGE_M

    ends = np.array([CLEAR_ON_HULLS, GOAL])
    hulls = ck.CollisionWorld(dataclasses.replace(ur10, exact_meshes={}), [], self_margin_m=0.01)
    nearest_m = float(hulls.self_collision.distances(ends)[0].min())  # on the hulls
    meshes = ck.CollisionWorld(ur10, [], self_margin_m=0.01)
    assert float(meshes.self_collision.distances(ends)[0].min()) > nearest_m + 0.001  # the meshes: clear
    for beyond_m, on in ((VERIFY_STEP_RANGE_M[0] / 2, False), (2 * VERIFY_STEP_RANGE_M[0], True)):
        scene = parse_scene({**ur10_scene(CLEAR_ON_HULLS), "self_margin": nearest_m - beyond_m})
        assert (on_hulls(build_problem(scene, ur10)) is not None) is on


def test_the_hulls_search_draws_a_share_of_the_samples(ur10: ck.Robot) -> None:
    problem = build_problem(parse_scene(ur10_scene(CLEAR_ON_HULLS)), ur10)
    hulls = on_hulls(problem)
    assert hulls is not None
    drawn = hulls.scene.planner.tuning.seeding.max_samples
    assert drawn == int(problem.scene.planner.tuning.seeding.max_samples * HULLS_SHARE) < 50_000
    assert hulls.objective.world is hulls.world and not hulls.world.robot.exact_meshes


def test_check_says_which_model_it_certified_on(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = tmp_path / "ur10.yaml"
    scene.write_text(yaml.safe_dump(ur10_scene(CLEAR_ON_HULLS)))
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 0
    capsys.readouterr()
    assert main(["check", str(scene), str(tmp_path / "out" / "trajectory.json")]) == 0
    said = capsys.readouterr().out
    assert "verified against" in said and "on the exact meshes of 5 links" in said
    assert "coal's tolerance: 1e-6 of a distance" in said


def test_the_meshes_draw_goes_on_with_the_trees_the_hulls_grew(
    ur10: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ball across the way: the hulls' quarter of the samples finds no path, the meshes' draw
    goes on from the hulls' trees and needs fewer samples than from its ends; certified on the meshes."""
    scene = parse_scene({**ur10_scene(CLEAR_ON_HULLS), "obstacles": [BALL]})
    tuning = scene.planner.tuning
    tuning = dataclasses.replace(tuning, seeding=dataclasses.replace(tuning.seeding, max_samples=400))
    scene = dataclasses.replace(scene, planner=dataclasses.replace(scene.planner, tuning=tuning))
    draws: list[tuple[int, int, int | None]] = []  # trees' nodes taken, nodes left, samples of a path

    def recorded(*args: Any, **kwargs: Any) -> Any:
        grown: GrownTrees | None = args[10]
        taken = 0 if grown is None else grown.nodes
        found = rrt_connect(*args, **kwargs)
        draws.append((taken, 0 if grown is None else grown.nodes, None if found is None else found.samples))
        return found

    monkeypatch.setattr(path_seeds, "rrt_connect", recorded)
    result = plan(scene, ur10)
    (_, left, none), (taken, _, samples) = draws  # the hulls' draw, then the meshes'
    assert none is None and left > 2 and taken == left and samples is not None
    assert result.problem.robot.exact_meshes  # planned on the meshes
    assert not verify_for_scene(build_problem(scene, ur10), result.trajectory).problems
    draws.clear()
    monkeypatch.setattr(planner, "shared_trees", lambda hulls, meshes: None)  # each draw from its ends
    plan(scene, ur10)
    (_, _, none), (taken, _, fresh) = draws
    assert none is None and taken == 0 and fresh is not None and samples < fresh


def test_the_check_tries_the_finer_step_of_the_hulls_where_the_ends_come_nearer_there(
    ur10: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A ball 0.4 mm beyond the margin of the start's hulls, 20 mm beyond its meshes: a plan on the
    hulls may be certified at half that 0.4 mm, finer than the meshes' finer step (1 mm), and
    ``check``, on the meshes, tries it after the scene's step and the meshes' (found on
    MotionBenchMaker's UR5 table_under_pick_0084: certified by the planner, refused by ``check``)."""
    centre, margin = (0.26, 0.55, 0.1), 0.02
    probe = ck.CollisionWorld(ur10, [ck.Obstacle.sphere(0.01, centre)])
    start = np.array(CLEAR_ON_HULLS)[None]
    on_meshes_m = float(probe.min_clearance_batch(start)[0][0])
    on_hulls_m = float(probe.on_hulls().min_clearance_batch(start)[0][0])
    assert on_meshes_m - on_hulls_m > 0.01  # the hulls reach 1 cm and more beyond the meshes there
    ball = {**BALL, "radius": 0.01 + on_hulls_m - margin - 0.0004, "xyz": list(centre)}
    scene = parse_scene({**ur10_scene(CLEAR_ON_HULLS), "safety_margin": margin, "obstacles": [ball]})
    problem = build_problem(scene, ur10)
    hulls = on_hulls(problem)
    assert hulls is not None
    steps = finer_steps_m(problem)
    assert steps == (finer_step_m(problem), finer_step_m(hulls))
    assert finer_step_m(problem) == scene.planner.finer_verify_step_m  # the meshes' ends are far enough
    assert math.isclose(steps[1], 0.0002, rel_tol=1e-6)  # half the hulls' 0.4 mm beyond the margin
    tried: list[float] = []

    def refused(world: ck.CollisionWorld, trajectory: Any, required: Any) -> Any:
        tried.append(required.step_m)
        return dataclasses.replace(verification, problems=("refused",))

    trajectory = plan(scene, ur10).trajectory
    verification = verify_for_scene(problem, trajectory)
    assert verification.accepted
    monkeypatch.setattr(verification_module, "verify_trajectory", refused)
    assert verify_for_scene(problem, trajectory).problems == ("refused",)
    assert tried == [scene.planner.verify_step_m, *steps]  # coarsest first, each once
    tried.clear()  # the planner's own verification of a motion it planned on these meshes: their step alone
    verify_finer_where_needed(problem, trajectory, Requirements.of(problem))
    assert tried == [scene.planner.verify_step_m, steps[0]]
    assert finer_steps_m(build_problem(parse_scene(ur10_scene(CLEAR_ON_MESHES)), ur10)) == (
        scene.planner.finer_verify_step_m,
    )  # ends that only the meshes clear: no plan on the hulls, one finer step


def test_check_tries_the_step_its_file_records_first_and_builds_no_other_where_it_certifies(
    ur10: ck.Robot, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The recorded step (``metrics.certified_step``) after the scene's: where it certifies, the hulls'
    problem is not built for their finer step; where it does not, the planner's steps follow; a
    recorded step coarser than the scene's is not taken (a coarser step would loosen the bound)."""
    from planning.pipeline import hulls_first

    scene = parse_scene({**ur10_scene(CLEAR_ON_HULLS), "obstacles": [BALL]})
    problem = build_problem(scene, ur10)
    trajectory = plan(scene, ur10).trajectory
    accepted = verify_for_scene(problem, trajectory)
    assert accepted.accepted
    step_m, recorded_m = scene.planner.verify_step_m, 0.0003
    tried: list[float] = []

    def certifies_at(step: float) -> Any:
        def verify(world: ck.CollisionWorld, trajectory: Any, required: Any) -> Any:
            tried.append(required.step_m)
            return accepted if required.step_m <= step else dataclasses.replace(accepted, problems=("no",))

        return verify

    def not_built(problem: Any) -> Any:
        raise AssertionError("the hulls' finer step was built")

    monkeypatch.setattr(verification_module, "verify_trajectory", certifies_at(recorded_m))
    monkeypatch.setattr(hulls_first, "finer_steps_m", not_built)
    assert verify_for_scene(problem, trajectory, certified_step_m=recorded_m).accepted
    assert tried == [step_m, recorded_m]
    monkeypatch.undo()
    steps = finer_steps_m(problem)
    tried.clear()
    monkeypatch.setattr(verification_module, "verify_trajectory", certifies_at(0.0))  # refuses every step
    assert not verify_for_scene(problem, trajectory, certified_step_m=recorded_m).accepted
    assert tried == [step_m, recorded_m, *steps]
    tried.clear()
    assert not verify_for_scene(problem, trajectory, certified_step_m=2 * step_m).accepted
    assert tried == [step_m, *steps]  # the coarser recorded step skipped
