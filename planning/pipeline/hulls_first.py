"""The hulls first: a robot with exact link meshes is planned on their convex hulls, then on the meshes.

Where a link's convex hull reaches beyond its mesh (:mod:`cpr_kin.shapes.exact_meshes`), the
collision model decides on the mesh, which costs triangle queries; the hulls contain the
meshes, so a trajectory certified on them is certified on the meshes too, and they ask coal
no triangle query. :func:`~planning.pipeline.planner.solve` therefore plans a problem whose
start and goal keep the margins on the hulls there first (:func:`on_hulls`), with
:data:`HULLS_SHARE` of the samples and of a time limit to find a feasible candidate (one
found is refined and chosen on to the plan's own limit,
:attr:`~planning.pipeline.deadline.Deadline.feasible_at_s`); where that finds no trajectory, the
meshes plan it in the time left, RRT-Connect going on with the trees the hulls' draw grew
(:class:`~planning.search.rrt_trees.GrownTrees`). Why a quarter: ``docs/tuning.md``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator

import numpy as np

from planning.pipeline.objective import PathRules, WaypointObjective
from planning.pipeline.problem import Problem, finer_step_m
from planning.pipeline.settings import VERIFY_STEP_RANGE_M
from planning.search.rrt_trees import GrownTrees

HULLS_SHARE = 0.25
"""The share of RRT-Connect's samples (``max_samples``) and of a time limit that a plan on the
hulls alone may take (:func:`on_hulls`); where it finds nothing in them, the meshes' turn."""


def on_hulls(problem: Problem) -> Problem | None:
    """``problem`` on its robot's convex hulls alone, where its start and goal clear the margins there.

    ``None`` for a robot whose meshes are all their own hulls, within a millimetre
    (:attr:`cpr_kin.Robot.exact_meshes` empty), or ends that only the exact meshes clear: by
    the margins plus the finest certified step (:data:`~planning.pipeline.settings.VERIFY_STEP_RANGE_M`),
    the least clearance beyond the margins that the fitness requires of every sample of a path,
    its ends too, under any relaxation of the step (:func:`~planning.pipeline.problem.finer_step_m`);
    ends nearer on the hulls leave their search nothing feasible. A
    hull contains its mesh, so a trajectory certified on the hulls is certified on the meshes;
    and the hulls ask coal no triangle query. Its sampling planner draws :data:`HULLS_SHARE`
    of the samples: a passage that only the meshes open is not searched for long on the hulls.
    """
    if not problem.robot.exact_meshes:
        return None
    world, scene = problem.world.on_hulls(), problem.scene
    ends, finest_m = np.stack([problem.q_start, problem.q_goal]), VERIFY_STEP_RANGE_M[0]
    if not world.keeps_clearance(ends, scene.safety_margin + finest_m, scene.self_margin + finest_m).all():
        return None
    tuning = scene.planner.tuning
    fewer = max(1, int(tuning.seeding.max_samples * HULLS_SHARE))
    seeding = dataclasses.replace(tuning.seeding, max_samples=fewer)
    planner = scene.planner.updated(tuning=dataclasses.replace(tuning, seeding=seeding))
    rules = PathRules(scene.safety_margin, scene.self_margin, problem.gravity)
    solver, duration = problem.solver, problem.duration  # the search's knots: not the world's
    objective = WaypointObjective(world, problem.motion, rules, planner, solver, duration)
    scene = dataclasses.replace(scene, planner=planner)
    return dataclasses.replace(problem, scene=scene, robot=world.robot, world=world, objective=objective)


def finer_steps_m(problem: Problem) -> tuple[float, ...]:
    """The finer certified steps [m] a plan of ``problem`` may be certified at, coarsest first.

    :func:`~planning.pipeline.problem.finer_step_m` of ``problem`` and, where it is planned on
    its hulls first (:func:`on_hulls`), of the hulls' problem: the ends come nearer the margins
    on the hulls, so its finer step may be finer still (half their clearance beyond the
    margins). ``cpr-plan check`` tries them in turn where the scene's steps cannot certify a
    trajectory (:func:`~planning.pipeline.verification.verify_finer_where_needed`), so that
    what the planner certified on the hulls, the check certifies on the meshes they contain.
    """
    steps = {finer_step_m(problem)}
    hulls = on_hulls(problem)
    if hulls is not None:
        steps.add(finer_step_m(hulls))
    return tuple(sorted(steps, reverse=True))


def check_steps_m(problem: Problem, recorded_m: float | None = None) -> Iterator[float]:
    """The finer steps [m] ``cpr-plan check`` tries in turn where the scene's cannot certify a trajectory.

    ``recorded_m`` first: the step its file says it was certified at (``metrics.certified_step``),
    the one most likely to certify it; then :func:`finer_steps_m`, built only if asked for
    (on a robot of meshes it builds the hulls' problem).
    """
    if recorded_m is not None:
        yield recorded_m
    yield from (step_m for step_m in finer_steps_m(problem) if step_m != recorded_m)


def shared_trees(hulls: Problem, meshes: Problem) -> GrownTrees:
    """Where the meshes' RRT-Connect draw goes on with the trees of the hulls' draw, where they agree.

    The hulls' trees keep the clearance on the hulls, so on the meshes they contain; trees
    that grew on under the finer step's clearance (a relaxation,
    :mod:`planning.pipeline.seeding`) keep that step's, which depends on how near the ends
    come to the margins (:func:`~planning.pipeline.problem.finer_step_m`), nearer on the
    hulls: taken only where both finer steps are one, asked only when the hulls' draw left
    trees (the steps cost distance queries on the meshes).
    """
    return GrownTrees(lambda: finer_step_m(hulls) == finer_step_m(meshes))
