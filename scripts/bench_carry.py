"""Upright carries, ours beside roboplan's constrained RRT-Connect, on the same problems in one run.

    python scripts/bench_carry.py [--problems 10] [--seed 1] [--robots panda ur5]

For each robot, ``--problems`` seeded carries: the tool pointing down above a point at a random
bearing and reach, to another 0.8 to 1.4 rad further round, a post between them as tall as
the carry is high (a way round it, not over), the tool's z axis to stay within 5 degrees of
straight down all the way, yaw free. Both ends are the same configurations for both planners
(our IK, the ends clear of the post and the robot itself by the margin). Ours is a task's free
motion under an :class:`~planning.task.orientation.OrientationConstraint`
(:func:`planning.task.plan_free`: the planner's free path bent onto it, or RRT-Connect on the
constraint; jerk-limited, the angle certified); the peer is roboplan's RRT-Connect with a
``PoseConstraint`` (roll and pitch within 5 degrees / sqrt(2) each) and TOPP-RA
(:mod:`planning.bench.roboplan_carry`). Both are warm library calls, alternated problem by
problem, the peer with a time limit of 10 s. One oracle measures both every millisecond of the
returned trajectory: the tilt of the tool's z axis (forward kinematics, ``arccos``), the
clearance from the post (coal), whether it ends at the goal, and the peak velocity,
acceleration and jerk over the limits (ours by exact extrema; roboplan's by finite differences
of its 1 ms samples).
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

import cpr_kin as ck
from cpr_kin.kinematics.ik_target import IkTarget
from cpr_kin.kinematics.numerical_ik import solve_ik
from planning.bench.roboplan_carry import RoboplanCarry
from planning.cli.arguments import COUNT, SEED
from planning.errors import NoSolutionError, PlanningError
from planning.io.robot_entry import robot_spec_of
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.verification import Requirements
from planning.task import OrientationConstraint, plan_free

ANGLE_RAD = math.radians(5.0)
MARGIN_M = 0.02
DOWN = np.asarray(pin.rpy.rpyToMatrix(math.pi, 0.0, 0.0))
X, Y, Z, W = (float(v) for v in pin.Quaternion(DOWN).coeffs())
QUAT_DOWN = (X, Y, Z, W)
ROOT = Path(__file__).resolve().parents[1]
SEEDS = {"panda": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8], "ur5": [0.0, -1.57, 1.57, -1.57, -1.57, 0.0]}
"""Where each arm's IK starts: the tool pointing down."""
NAN = math.nan


@dataclass(frozen=True)
class Run:
    """One planner on one carry, as the oracle measured it."""

    solved: bool
    planning_s: float
    duration_s: float = NAN
    tilt_rad: float = NAN
    clearance_m: float = NAN
    jerk_usage: float = NAN


@dataclass(frozen=True)
class Carry:
    """One problem: the scene (the post, the ends) and its ends' configurations."""

    scene: Scene
    q_start: np.ndarray
    q_goal: np.ndarray


def draw_carries(name: str, count: int, seed: int) -> list[Carry]:
    """``count`` carries of the arm ``name`` (module docstring), each with both ends clear."""
    rng = np.random.default_rng(seed)
    spec = robot_spec_of(name, ROOT)
    robot = spec.load()
    carries: list[Carry] = []
    while len(carries) < count:
        bearing, turn = rng.uniform(-1.2, -0.4), rng.uniform(0.8, 1.4)
        reach, height = rng.uniform(0.4, 0.55), rng.uniform(0.2, 0.4)
        ends = []
        for angle in (bearing, bearing + turn):
            target = IkTarget(
                position=np.array([reach * math.cos(angle), reach * math.sin(angle), height]), rotation=DOWN
            )
            try:
                ends.append(solve_ik(robot, target, seed_q=SEEDS[name]))
            except ck.CprKinError:
                break
        if len(ends) < 2:
            continue
        middle = bearing + turn / 2
        post = ck.Obstacle.box(
            (0.08, 0.08, height + 0.1),
            (reach * math.cos(middle), reach * math.sin(middle), (height + 0.1) / 2),
            name="post",
        )
        scene = Scene(
            name=f"{name} carry {len(carries)}",
            robot=spec,
            safety_margin=MARGIN_M,
            start=Target(q=tuple(ends[0].tolist())),
            goal=Target(q=tuple(ends[1].tolist())),
            obstacles=(post,),
        )
        try:
            build_problem(scene, robot)  # both ends clear of the post and the robot itself
        except PlanningError:
            continue
        carries.append(Carry(scene, ends[0], ends[1]))
    return carries


def tilt_and_clearance(world: ck.CollisionWorld, positions: np.ndarray) -> tuple[float, float]:
    """The oracle: the largest tilt of the tool's z axis from straight down [rad], the least clearance [m]."""
    z_axes = ck.frame_poses(world.robot, positions)[:, :3, 2]
    tilt = float(np.arccos(np.clip(z_axes @ DOWN[:, 2], -1.0, 1.0)).max())
    return tilt, float(world.min_clearance_batch(positions)[0].min())


def our_run(carry: Carry, robot: ck.Robot) -> Run:
    """Our free motion under the constraint, timed, and the oracle's measures of its trajectory."""
    problem = build_problem(carry.scene, robot)
    constraint = OrientationConstraint(("x", "y"), ANGLE_RAD, quat_xyzw=QUAT_DOWN)
    started = time.perf_counter()
    try:
        free = plan_free(carry.scene, robot, constraint, Requirements.of(problem))
    except NoSolutionError:
        return Run(False, time.perf_counter() - started)
    elapsed = time.perf_counter() - started
    trajectory = free.trajectory
    times = np.append(np.arange(trajectory.knots[0], trajectory.knots[-1], 1e-3), trajectory.knots[-1])
    positions = trajectory(times)
    tilt, clearance = tilt_and_clearance(problem.world, positions)
    reached = bool(np.abs(positions[-1] - carry.q_goal).max() <= 1e-6)
    jerk = float(np.max(trajectory.extrema(3).peak / robot.limits.jerk))
    return Run(reached, elapsed, trajectory.duration, tilt, clearance, jerk)


def peer_run(carry: Carry, peer: RoboplanCarry, seed: int) -> Run:
    """The peer's constrained carry, timed, and the oracle's measures of its samples."""
    robot, world = peer.peer.problem.robot, peer.peer.problem.world
    found = peer.plan(carry.q_start, carry.q_goal, DOWN, ANGLE_RAD, 10.0, seed)
    if not found.success:
        return Run(False, found.planning_time_s)
    tilt, clearance = tilt_and_clearance(world, found.positions)
    reached = bool(np.abs(found.positions[-1] - carry.q_goal).max() <= 1e-6)
    jerks = found.positions
    for _ in range(3):
        jerks = np.diff(jerks, axis=0) / np.diff(found.times)[: len(jerks) - 1, None]
    jerk = float(np.max(np.abs(jerks) / robot.limits.jerk)) if len(jerks) else NAN
    return Run(reached, found.planning_time_s, float(found.times[-1]), tilt, clearance, jerk)


def median(values: list[float]) -> float:
    """The median, ``nan`` of nothing."""
    return statistics.median(values) if values else NAN


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--problems", type=COUNT, default=10)
    parser.add_argument("--seed", type=SEED, default=1)
    parser.add_argument("--robots", nargs="+", choices=sorted(SEEDS), default=sorted(SEEDS))
    args = parser.parse_args()
    print(
        "| robot | carries | solved ours / roboplan | median planning [ms] ours / roboplan (ratio) "
        "| median duration [s] on both solved, ours / roboplan (ratio) | largest tilt sampled [deg] "
        "ours / roboplan (allowed 5) | least clearance [mm] ours / roboplan (margin 20) "
        "| peak jerk over limit ours / roboplan |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in args.robots:
        carries = draw_carries(name, args.problems, args.seed)
        robot = carries[0].scene.robot_spec().load()
        ours, theirs = [], []
        for k, carry in enumerate(carries):
            ours.append(our_run(carry, robot))
            theirs.append(peer_run(carry, RoboplanCarry(carry.scene, robot), args.seed + k))
        both = [k for k in range(len(carries)) if ours[k].solved and theirs[k].solved]
        planning = [median([run.planning_s * 1e3 for run in side]) for side in (ours, theirs)]
        durations = [median([side[k].duration_s for k in both]) for side in (ours, theirs)]
        tilts = [
            max((math.degrees(r.tilt_rad) for r in side if r.solved), default=NAN) for side in (ours, theirs)
        ]
        clear = [min((r.clearance_m * 1e3 for r in side if r.solved), default=NAN) for side in (ours, theirs)]
        jerks = [max((r.jerk_usage for r in side if r.solved), default=NAN) for side in (ours, theirs)]
        solved = [sum(r.solved for r in side) for side in (ours, theirs)]
        print(
            f"| {name} | {len(carries)} | {solved[0]} / {solved[1]} | {planning[0]:.0f} / {planning[1]:.0f} "
            f"({planning[0] / planning[1]:.1f}) | {durations[0]:.2f} / {durations[1]:.2f} "
            f"({durations[0] / durations[1]:.2f}) | {tilts[0]:.2f} / {tilts[1]:.2f} "
            f"| {clear[0]:.1f} / {clear[1]:.1f} | {jerks[0]:.2f} / {jerks[1]:.1f} |",
            flush=True,
        )


if __name__ == "__main__":
    main()
