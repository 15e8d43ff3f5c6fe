"""pyroboplan's RRT-Connect as a sampling baseline, on our URDF, scene and checks.

pyroboplan (``pip install --no-deps pyroboplan``, see the README) plans on a Pinocchio model
and collision model. It gets the CPR reduced to the moving joints
(``pinocchio.buildReducedModel`` locks the others at their start values) and our collision
world's geometry, robot-obstacle pairs only, with the planning clearance
(:func:`planning.bench.toppra_timing.planning_clearance_m`) as its distance padding.
Its own shortcutting checks collisions without that padding, so the path is shortcut here,
against that clearance; TOPP-RA timing and the certified verification are those of
:func:`planning.bench.toppra_timing.time_and_verify`.
"""

from __future__ import annotations

import contextlib
import io
import time
from collections.abc import Callable

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from planning.bench.toppra_timing import SamplingResult, planning_clearance_m, time_and_verify
from planning.pipeline.blas_threads import one_blas_thread
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]


@one_blas_thread  # as our planner runs: the same machine for both (blas_threads)
def plan_pyroboplan_rrt_connect(
    scene: Scene, robot: ck.Robot | None = None, time_limit_s: float = 2.0, seed: int = 0
) -> SamplingResult:
    """Plan ``scene`` with pyroboplan's bidirectional RRT-Connect, shortcut, TOPP-RA, verify.

    The step and connection range match the OMPL baseline's: collision checks every
    0.2 % and tree extensions of at most 20 % of the moving joints' range diagonal.
    pyroboplan draws from NumPy's global generator; it is seeded with ``seed`` and restored
    afterwards, and its progress messages are silenced.
    """
    from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions

    started = time.perf_counter()
    problem = build_problem(scene, robot)
    robot, world, moving = problem.robot, problem.world, problem.moving
    q_start, q_goal = problem.q_start, problem.q_goal
    locked = [robot.model.getJointId(name) for i, name in enumerate(robot.joint_names) if i not in moving]
    model, geometry = pin.buildReducedModel(robot.model, world.geometry_model, locked, q_start)
    clearance_m = planning_clearance_m(scene)
    extent = float(np.linalg.norm(robot.limits.range[moving]))
    options = RRTPlannerOptions(
        max_step_size=0.002 * extent,
        max_connection_dist=0.2 * extent,
        rrt_connect=True,
        bidirectional_rrt=True,
        max_planning_time=time_limit_s,
        rng_seed=seed,
        fast_return=True,
        collision_distance_padding=clearance_m,
    )
    state = np.random.get_state()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            path = RRTPlanner(model, geometry, options).plan(q_start[moving], q_goal[moving])
    finally:
        np.random.set_state(state)
    if not path:
        return SamplingResult.failure(
            f"pyroboplan's RRT-Connect found no path in {time_limit_s} s", robot.nq, started
        )
    waypoints = np.tile(q_start, (len(path), 1))
    waypoints[:, moving] = np.asarray(path)

    def segment_clear(a: FloatArray, b: FloatArray) -> bool:
        count = max(2, int(np.ceil(np.linalg.norm((b - a)[moving]) / options.max_step_size)) + 1)
        line = a + np.linspace(0.0, 1.0, count)[:, None] * (b - a)
        return not bool(world.margin_violated(line, clearance_m).any())

    shortcut = shortcut_path(waypoints, segment_clear, np.random.default_rng(seed))
    return time_and_verify(robot, world, scene, shortcut, started)


def shortcut_path(
    waypoints: FloatArray,
    segment_clear: Callable[[FloatArray, FloatArray], bool],
    rng: np.random.Generator,
    attempts: int = 100,
) -> FloatArray:
    """Random shortcutting of a polyline ``(K, nq)`` in joint space.

    Each attempt draws two points along the path (by length) and, where the straight
    segment between them is clear, replaces the path between them by it. Start and goal
    stay; every segment of the result was checked by ``segment_clear`` (or was one of the
    input's).
    """
    path = np.asarray(waypoints, dtype=float)
    for _ in range(attempts):
        if len(path) < 3:
            break
        lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
        cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
        if cumulative[-1] <= 0.0:
            break
        low, high = np.sort(rng.uniform(0.0, cumulative[-1], 2))
        i, j = np.searchsorted(cumulative, [low, high], side="right") - 1
        if i == j:
            continue  # both on one straight segment: nothing to gain
        a = path[i] + (low - cumulative[i]) / lengths[i] * (path[i + 1] - path[i])
        b = path[j] + (high - cumulative[j]) / lengths[j] * (path[j + 1] - path[j])
        if segment_clear(a, b):
            path = np.vstack([path[: i + 1], a, b, path[j + 1 :]])
    return path
