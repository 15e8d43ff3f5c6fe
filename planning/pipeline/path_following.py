"""The last resort of a plan: follow the sampling planner's path itself, through its corners.

The search's trajectories are splines through a few waypoints: smooth and fast, but they cut
the corners of the path they follow. In a passage barely wider than the clearance every
one of them may touch it, and the plan would end in "no solution" although RRT-Connect
found a clear path (a false negative). So when the seeding has no attempt left
(:meth:`~planning.pipeline.seeding.PathSeeding.after`), :func:`follow_path` shortens that
path further (:func:`shortened`: a path the robot follows is worth more shortcuts than a
seed) and follows it closely, by the first of these motions that passes:

1. a spline that passes exactly through each vertex and through points evenly placed on each
   piece between them (:data:`POINTS_PER_PIECE` of them a piece, denser at each try), on
   centripetal knots (each piece's share of time the square root of its length: the spline
   keeps to the polyline at its corners, where chord-length knots overshoot), timed by the
   scene's duration rule like any candidate's path. The denser the points, the nearer the
   spline keeps to the path, and the slower it must turn at the corners. Through the
   shortened path first, then through the path as found, whose corners keep more room;
2. straight joint-space segments between the vertices of whichever path stops sooner (the
   shortcuts cut corners, and may add some), at rest at each
   (:func:`~planning.curves.stop_and_go.stop_and_go`): they sweep exactly the segments that
   were checked. Slower, as the robot stops at every corner; still jerk-limited and C3.

Each gets the same certified verification as every trajectory; the splines are tried only
while the plan's time limit has not passed.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, SplineFit
from planning.curves.stop_and_go import stop_and_go
from planning.pipeline.choose import Choice, Refusal, verify
from planning.pipeline.offered import Timing
from planning.pipeline.path_seeds import clearance_validity, edge_resolution_m
from planning.pipeline.problem import Problem, with_planner
from planning.pipeline.settings import MAX_WAYPOINTS
from planning.search.edges import Edges, shortcut
from planning.search.waypoints import waypoints_along

FloatArray = NDArray[np.float64]
SHORTCUTS = 400
"""Random shortcuts tried on the path before it is followed (``docs/tuning.md``)."""
POINTS_PER_PIECE = (2, 4, 8)
"""The splines through the path: points per piece between two vertices, in the order tried
(``docs/tuning.md``)."""


def follow_path(problem: Problem, path: FloatArray) -> tuple[Problem, Choice | Refusal]:
    """The first verified motion that follows ``path`` ``(k, moving)`` (module docstring), and its problem.

    The problem returned has as many waypoints as the path followed has corners (at most
    :data:`~planning.pipeline.settings.MAX_WAYPOINTS`): the candidate's fitness terms in the
    result are those of the corners. A scene's fixed duration is kept when the path can be
    followed within it, else the trajectory is as fast as the limits allow and reported as
    stretched. The refusal, when none passes, is the stop-and-go motion's.
    """
    weights = ck.path_weights(problem.robot)[problem.moving]
    paths = (shortened(problem, path), path)
    for tried, (followed, timing) in enumerate(_motions(problem, paths, weights), start=1):
        verification = verify(problem, timing.trajectory, timing.fit)
        if verification.accepted:
            count = int(np.clip(len(followed) - 2, 1, MAX_WAYPOINTS))
            x = waypoints_along(followed, count, weights).ravel()
            choice = Choice(x, _vertices(problem, followed), timing, verification, tried)
            return with_planner(problem, waypoints=count), choice
    cause = "; ".join(verification.problems) or "its certified check fails"
    return problem, Refusal(f"following it vertex to vertex {cause}", verification.check)


def shortened(problem: Problem, path: FloatArray) -> FloatArray:
    """``path`` ``(k, moving)`` shortened by :data:`SHORTCUTS` random shortcuts, then vertices skipped.

    A vertex is skipped where a later one is in sight. The sampling planner shortens the paths
    it finds a little, as seeds of the search; a path the robot follows is worth more. The
    shortcuts keep the fitness's clearance, checked as the sampling planner checks its edges
    (:func:`~planning.search.edges.shortcut`), and draw from the stream
    ``default_rng([seed, 3])``.
    """
    edges = Edges(
        clearance_validity(problem),
        ck.path_weights(problem.robot)[problem.moving],
        edge_resolution_m(problem),
    )
    rng = np.random.default_rng([problem.scene.planner.seed, 3])
    return shortcut(path, edges, rng, SHORTCUTS)


def _vertices(problem: Problem, path: FloatArray) -> FloatArray:
    """``(k, nq)`` configurations of ``path``'s vertices, its ends exactly the problem's start and goal."""
    vertices = problem.configurations(path)
    vertices[0], vertices[-1] = problem.q_start, problem.q_goal
    return vertices


def _motions(
    problem: Problem, paths: tuple[FloatArray, FloatArray], weights: FloatArray
) -> Iterator[tuple[FloatArray, Timing]]:
    """The motions to verify, in order, each with the path it follows.

    The splines through the vertices of each of ``paths`` (the shortened path first: the more
    corners its shortcuts cut, the nearer it is to a curve; then the path as found, whose
    corners keep more room from the obstacles), each only when no slower than stopping and
    while the problem's deadline has not passed; then stopping at the vertices of whichever
    of ``paths`` stops sooner (the shortcuts may add corners).
    """
    distinct = paths[:1] if np.array_equal(*paths) else paths
    vertices = [_vertices(problem, path) for path in distinct]
    stops = [stop_and_go_timing(problem, corners) for corners in vertices]
    sooner = min(range(len(stops)), key=lambda k: stops[k].trajectory.duration)
    for path, corners in zip(distinct, vertices, strict=True):
        for points in POINTS_PER_PIECE:
            if problem.deadline.passed():
                break
            timing = through_vertices(problem, corners, weights, points)
            if timing.trajectory.duration <= stops[sooner].trajectory.duration:
                yield path, timing
    yield distinct[sooner], stops[sooner]


def stop_and_go_timing(problem: Problem, vertices: FloatArray) -> Timing:
    """The motion at rest at each of ``vertices`` ``(k, nq)``, straight between them, held to the rule."""
    started = time.perf_counter()
    limits = problem.robot.limits
    trajectory = stop_and_go(
        vertices, limits.velocity, limits.acceleration, limits.jerk, torque=problem.dynamics
    )
    trajectory, stretched = problem.duration.held(trajectory)
    fit = SplineFit(
        trajectory=trajectory,
        targets=vertices,
        nodes=np.stack([vertices, *([np.zeros_like(vertices)] * 3)], axis=-1),
        settings=problem.solver.settings,
    )
    return Timing(trajectory, "stop_and_go", fit, stretched, time.perf_counter() - started)


def through_vertices(problem: Problem, vertices: FloatArray, weights: FloatArray, points: int) -> Timing:
    """The first timing of the spline through ``vertices`` and ``points - 1`` more on each piece.

    The spline interpolates (``p = inf``, the scene's other spline settings kept) on
    centripetal knots spanning the duration rule's nominal duration, and is timed by the
    problem's duration rule (its first timing, :meth:`~planning.pipeline.timing.FreeDuration.timings`),
    reported as ``through_path``.

    Args:
        problem: the plan's problem.
        vertices: ``(k, nq)`` the path's vertices, start and goal included [rad, m].
        weights: ``(moving,)`` the moving joints' weights of a path's length [m/rad, m/m].
        points: points per piece, the vertex ending it included (1: the vertices alone).
    """
    shares = np.arange(1, points + 1) / points
    pieces = vertices[:-1, None] + shares[None, :, None] * np.diff(vertices, axis=0)[:, None]
    nodes = np.concatenate([vertices[:1], pieces.reshape(-1, vertices.shape[1])])
    lengths = np.abs(np.diff(nodes[:, problem.moving], axis=0)) @ weights
    steps = np.sqrt(np.maximum(lengths, 1e-12 * lengths.max(initial=1.0)))
    nominal_s = problem.duration.nominal_duration(len(steps))
    knots = np.concatenate([[0.0], np.cumsum(steps)]) * (nominal_s / steps.sum())
    settings = dataclasses.replace(problem.solver.settings, p=float("inf"))
    dense = dataclasses.replace(problem, solver=SepticSplineSolver(knots, settings))
    return dataclasses.replace(problem.duration.timings(dense, nodes).first, method="through_path")
