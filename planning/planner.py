"""The planner: scene -> firefly waypoints -> septic spline -> timing -> verified trajectory."""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, SplineFit, uniform_knots
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.objective import Breakdown, WaypointObjective
from planning.scene import Scene, paper_scene
from planning.search.baselines import Optimizer
from planning.search.firefly import FireflyProgress, FireflyResult, firefly_minimize
from planning.verification import Verification, verify_trajectory

FloatArray = NDArray[np.float64]

WRIST_JOINTS = ("theta4", "theta5")


class NoTrajectoryFoundError(PlanningError):
    """No candidate of the final population passed the verification.

    Attributes:
        certified_clearance_m: certified clearance of the best candidate [m].
        worst_time: when it comes closest [s].
        worst_pair: ``(robot geometry, obstacle)`` closest then.
        worst_group: the violating group.
    """

    def __init__(self, message: str, check: ck.CurveCheck) -> None:
        super().__init__(message)
        self.certified_clearance_m = check.certified_min_m
        self.worst_time = check.worst_time
        self.worst_pair = check.worst_pair
        self.worst_group = check.worst_group


@dataclass(frozen=True)
class Metrics:
    """Figures of a planned trajectory.

    Attributes:
        duration: trajectory duration [s].
        fitness: objective value of the chosen waypoints.
        t_sol: PTP time through the chosen nodes (the paper's objective value) [s].
        w_sol: normalised accumulated joint motion of the executed path.
        min_clearance: certified lower bound of the clearance along the trajectory [m].
        sampled_min_clearance: smallest clearance at the verification samples [m].
        max_node_deviation: largest |y_i - f_i| of the spline [rad or m].
        jerk_min: per joint, smallest jerk [rad/s^3 or m/s^3].
        jerk_max: per joint, largest jerk.
        limit_utilisation: largest |velocity|, |acceleration|, |jerk| over the limit, per order.
        integrated_squared_jerk: per joint [rad^2/s^5 or m^2/s^5].
        planning_time_s: wall time of :func:`plan` [s].
        optimiser_time_s: wall time of the firefly search [s].
        evaluations: objective evaluations.
        candidates_verified: candidates that went through the final verification.
        duration_stretched: the requested duration broke a limit and was stretched.
    """

    duration: float
    fitness: float
    t_sol: float
    w_sol: float
    min_clearance: float
    sampled_min_clearance: float
    max_node_deviation: float
    jerk_min: dict[str, float]
    jerk_max: dict[str, float]
    limit_utilisation: dict[str, float]
    integrated_squared_jerk: dict[str, float]
    planning_time_s: float
    optimiser_time_s: float
    evaluations: int
    candidates_verified: int
    duration_stretched: bool


@dataclass(frozen=True)
class PlanResult:
    """A planned, verified trajectory with everything that produced it.

    Attributes:
        scene: the scene planned.
        robot: the robot used.
        joint_names: joint order of every array.
        waypoints: ``(p + 2, nq)`` start, intermediate waypoints, goal [rad, m].
        trajectory: the timed septic spline.
        spline: the spline fit (on the nominal knots, before timing).
        time_scale: factor from the nominal knots to the trajectory's.
        metrics: figures of the result.
        breakdown: the chosen candidate's fitness terms.
        optimiser: the firefly run (history, population).
        verification: the certified continuous check of the trajectory.
    """

    scene: Scene
    robot: ck.Robot = field(repr=False)
    joint_names: tuple[str, ...]
    waypoints: FloatArray
    trajectory: Trajectory
    spline: SplineFit = field(repr=False)
    time_scale: float
    metrics: Metrics
    breakdown: Breakdown = field(repr=False)
    optimiser: FireflyResult = field(repr=False)
    verification: ck.CurveCheck = field(repr=False)


def moving_joints(robot: ck.Robot, scene: Scene, q_start: FloatArray, q_goal: FloatArray) -> NDArray[np.intp]:
    """Indices of the joints a plan moves.

    ``scene.planner.moving_joints``, or theta1, d2, d3 and each wrist joint whose start and
    goal values differ.
    """
    names = scene.planner.moving_joints
    if names is None:
        names = tuple(
            n
            for i, n in enumerate(robot.joint_names)
            if n not in WRIST_JOINTS or not np.isclose(q_start[i], q_goal[i])
        )
    if not names:
        raise PlanningError("moving_joints is empty; name at least one joint the waypoints may move")
    return np.array([robot.limits.index(n) for n in names], dtype=np.intp)


def endpoint(robot: ck.Robot, world: ck.CollisionWorld, scene: Scene, label: str) -> FloatArray:
    """The configuration of the scene's start or goal; refused if unreachable or inside the margin."""
    target = scene.start if label == "start" else scene.goal
    try:
        q = target.configuration(robot)
    except ck.CprKinError as exc:
        raise PlanningError(f"{label} is not reachable: {exc}") from None
    clearance = world.clearance(q)
    closest = clearance.closest
    if closest is not None and clearance.min_clearance_m < scene.safety_margin:
        raise PlanningError(
            f"{label} q = {np.round(q, 4).tolist()} is inside the safety margin: {closest.robot_geometry} "
            f"is {clearance.min_clearance_m:.3f} m from obstacle '{closest.obstacle}' "
            f"(margin {scene.safety_margin} m)"
        )
    return q


def _verify(world: ck.CollisionWorld, scene: Scene, trajectory: Trajectory, fit: SplineFit) -> Verification:
    """The scene's verification, plus the node-deviation bound of the planner settings."""
    verification = verify_trajectory(world, trajectory, scene.safety_margin, scene.planner.verify_step_m)
    bound = scene.planner.max_node_deviation
    if bound is not None and fit.max_node_deviation > bound:
        problem = (
            f"deviates {fit.max_node_deviation:.3g} from its nodes, more than max_node_deviation = {bound:g}"
        )
        verification = Verification(verification.check, (*verification.problems, problem))
    return verification


def plan(
    scene: Scene,
    robot: ck.Robot | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
    threads: int | None = None,
    optimizer: Optimizer | None = None,
) -> PlanResult:
    """Plan a collision-free, jerk-continuous trajectory for ``scene``.

    Steps: inverse kinematics of start and goal (reachable, clear of the margin); firefly
    search of the waypoints on the objective of :mod:`planning.objective`; septic spline
    through start, waypoints and goal on ``p + 1`` uniform segments; timing (the scene's
    duration, stretched if it breaks a velocity, acceleration or jerk limit, or the fastest
    uniform timing within them); certified continuous verification of the whole
    trajectory against the margin. If the best candidate fails the verification, the final
    population's other feasible candidates are tried in order of fitness.

    Args:
        scene: the problem and its settings.
        robot: a loaded robot (default: load ``scene.robot`` or the bundled CPR).
        progress: called after every firefly iteration.
        threads: threads of the parallel collision checks (default: up to 2); a batch that
            plans scenes in parallel processes gives each 1.
        optimizer: another optimiser of :mod:`planning.search.baselines` on the same objective and
            evaluation budget (``fireflies x (iterations + 1)``); default: the firefly.

    Raises:
        PlanningError: unreachable start or goal, or one inside the margin; bad settings.
        NoTrajectoryFoundError: no candidate passes the verification.
    """
    started = time.perf_counter()
    robot = robot or ck.load_cpr(scene.robot)
    world = ck.CollisionWorld(robot, scene.obstacles, num_threads=threads)
    q_start = endpoint(robot, world, scene, "start")
    q_goal = endpoint(robot, world, scene, "goal")
    settings = scene.planner
    moving = moving_joints(robot, scene, q_start, q_goal)
    segments = settings.waypoints + 1
    nominal_duration = scene.duration if scene.duration is not None else float(segments)
    solver = SepticSplineSolver(uniform_knots(segments, nominal_duration), scene.spline)
    objective = WaypointObjective(
        world,
        q_start,
        q_goal,
        moving,
        scene.safety_margin,
        settings,
        solver,
        timed=scene.duration is not None,
    )

    search_started = time.perf_counter()
    rng = np.random.default_rng(settings.seed)
    if optimizer is None:
        result = firefly_minimize(
            objective, objective.lower, objective.upper, settings.firefly(), rng, progress
        )
    else:
        budget = settings.fireflies * (settings.iterations + 1)
        result = optimizer(objective, objective.lower, objective.upper, budget, rng)
    optimiser_time = time.perf_counter() - search_started

    limits = robot.limits
    # the best, then the final population's candidates the fitness found feasible (an
    # infeasible one will not pass the verification), best first
    order = np.argsort(result.population_fitness, kind="stable")
    feasible = result.population_fitness <= objective.t_max  # both fitnesses rank feasible at or below t_max
    candidates = [result.x] + [result.population[k] for k in order if feasible[k]]
    first: Verification | None = None
    tried = 0
    for x in candidates:
        tried += 1
        nodes = objective.nodes(x[None])[0]
        fit = solver.solve(nodes)
        nominal = fit.trajectory
        scale = nominal.time_scale_for_limits(limits.velocity, limits.acceleration, limits.jerk)
        stretched = scene.duration is not None and scale > 1.0
        if scene.duration is not None:
            scale = max(scale, 1.0)
        trajectory = nominal.time_scaled(scale)
        verification = _verify(world, scene, trajectory, fit)
        first = first or verification
        if verification.accepted:
            break
    else:
        assert first is not None  # candidates is never empty
        raise NoTrajectoryFoundError(
            f"no collision-free trajectory found: the best candidate {'; '.join(first.problems)} "
            f"({len(candidates)} candidates verified)",
            first.check,
        )
    check = verification.check

    breakdown = objective.breakdown(x[None])
    names = robot.joint_names
    jerk = trajectory.extrema(3)
    utilisation = {
        kind: float(np.max(trajectory.extrema(r).peak / limit))
        for r, (kind, limit) in enumerate(
            (("velocity", limits.velocity), ("acceleration", limits.acceleration), ("jerk", limits.jerk)),
            start=1,
        )
    }
    metrics = Metrics(
        duration=trajectory.duration,
        fitness=float(breakdown.fitness[0]),
        t_sol=float(breakdown.t_sol[0]),
        w_sol=float(breakdown.w_sol[0]),
        min_clearance=check.certified_min_m,
        sampled_min_clearance=check.sampled_min_m,
        max_node_deviation=fit.max_node_deviation,
        jerk_min=dict(zip(names, map(float, jerk.minimum), strict=True)),
        jerk_max=dict(zip(names, map(float, jerk.maximum), strict=True)),
        limit_utilisation=utilisation,
        integrated_squared_jerk=dict(zip(names, map(float, trajectory.integrated_squared_jerk), strict=True)),
        planning_time_s=time.perf_counter() - started,
        optimiser_time_s=optimiser_time,
        evaluations=result.evaluations,
        candidates_verified=tried,
        duration_stretched=bool(stretched),
    )
    return PlanResult(
        scene=scene,
        robot=robot,
        joint_names=names,
        waypoints=nodes,
        trajectory=trajectory,
        spline=fit,
        time_scale=float(scale),
        metrics=metrics,
        breakdown=breakdown,
        optimiser=result,
        verification=check,
    )


def warm_up(robot: ck.Robot | None = None) -> float:
    """Compile the numba kernels, or load them from their on-disk cache; seconds spent.

    Planning does it anyway on its first call; this moves the one-time cost (several
    seconds on a new machine, a fraction of a second per process afterwards) out of a plan
    that is timed. It plans the paper case with two fireflies for one iteration.
    """
    started = time.perf_counter()
    with contextlib.suppress(PlanningError):  # a search this small may find nothing: the kernels ran
        plan(paper_scene(fireflies=2, iterations=1), robot, threads=1)
    return time.perf_counter() - started
