"""OMPL's RRT-Connect with path simplification and TOPP-RA timing, a sampling-planner peer.

The same scene, URDF, collision world and limits as the firefly planner
(:func:`planning.pipeline.problem.build_problem`): RRT-Connect searches the moving joints with our
coal margin checks as state validity (the margin, and the self margin between the robot's own
checked pairs, each plus the verification step, the clearances the firefly's fitness asks of
its samples; with a start or goal inside those, the seeding's finer step, as ours), the path
is simplified, and :func:`planning.bench.toppra_timing.time_and_verify` times and verifies it. The peer is
optional (``pip install '.[bench]'``).
"""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.bench.toppra_timing import SamplingResult, import_toppra, time_and_verify
from planning.pipeline.blas_threads import one_blas_thread
from planning.pipeline.problem import build_problem, finer_step_m, with_planner
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]


def import_peer() -> None:
    """Import OMPL's bindings and TOPP-RA, which :func:`plan_rrt_connect` imports on its first call.

    A benchmark calls it before timing the pipeline warm, as it compiles our kernels before
    timing ours.
    """
    from ompl import base, geometric, util  # noqa: F401

    import_toppra()


@one_blas_thread  # as our planner runs: the same machine for both (blas_threads)
def plan_rrt_connect(
    scene: Scene, robot: ck.Robot | None = None, time_limit_s: float = 2.0, seed: int = 0
) -> SamplingResult:
    """Plan ``scene`` with RRT-Connect + simplification + TOPP-RA, then verify."""
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    started = time.perf_counter()
    problem = build_problem(scene, robot)
    robot, world, moving = problem.robot, problem.world, problem.moving
    q_start, q_goal = problem.q_start, problem.q_goal
    limits = robot.limits

    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    ou.RNG.setSeed(seed + 1)  # OMPL refuses seed 0
    space = ob.RealVectorStateSpace(int(moving.size))
    bounds = ob.RealVectorBounds(int(moving.size))
    for i, j in enumerate(moving):
        bounds.setLow(i, float(limits.lower[j]))
        bounds.setHigh(i, float(limits.upper[j]))
    space.setBounds(bounds)
    information = ob.SpaceInformation(space)

    def full(state: object) -> FloatArray:
        q = q_start.copy()
        q[moving] = [state[i] for i in range(moving.size)]  # type: ignore[index]
        return q

    ends, objective = np.stack([q_start, q_goal]), problem.objective
    if not world.keeps_clearance(ends, objective.required_m, objective.required_self_m).all():
        # an end within margin plus step (a grasp): the finer step, as the firefly's seeding
        problem = with_planner(problem, verify_step_m=finer_step_m(problem))
        scene, objective = problem.scene, problem.objective
    margin_m, self_margin_m = objective.required_m, objective.required_self_m  # the fitness's clearances

    def valid(state: object) -> bool:
        return bool(world.keeps_clearance(full(state)[None], margin_m, self_margin_m)[0])

    information.setStateValidityChecker(valid)
    information.setStateValidityCheckingResolution(0.002)  # of the space's extent, ~1.2 cm in theta1
    information.setup()
    start_state, goal_state = space.allocState(), space.allocState()
    for i, j in enumerate(moving):
        start_state[i], goal_state[i] = float(q_start[j]), float(q_goal[j])
    setup = og.SimpleSetup(information)
    setup.setStartAndGoalStates(start_state, goal_state)
    setup.setPlanner(og.RRTConnect(information))
    if not setup.solve(time_limit_s) or not setup.haveExactSolutionPath():
        return SamplingResult.failure(f"RRT-Connect found no path in {time_limit_s} s", robot.nq, started)
    setup.simplifySolution()
    path = setup.getSolutionPath()
    waypoints = np.array([full(path.getState(i)) for i in range(path.getStateCount())])

    return time_and_verify(robot, world, scene, waypoints, started)
