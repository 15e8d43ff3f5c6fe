"""Straight tool lines, ours beside roboplan's Cartesian path planner, on the same lines in one run.

    python scripts/bench_lines.py [--lines 20] [--seed 1] [--robots cpr panda ur5]

For each robot, ``--lines`` seeded random lines: a start configuration drawn within the joint
ranges and 1 cm clear of the robot itself, a direction (any, for an arm of six or more joints; in
the plane of the arm's column and its reach for the CPR, the directions a five-joint arm can
hold its orientation along) and a length of 5 to 20 cm, the orientation kept. Ours is
:func:`planning.task.plan_line` (jerk-limited, deviation certified); the peer is roboplan's
``CartesianPathPlanner``, time-optimal under the velocity and acceleration limits
(:mod:`planning.bench.roboplan_lines`), both with a 1 mm and 0.01 rad tolerance and no contact
allowed (ours certified, roboplan's samples checked). Both are
warm library calls, alternated line by line. One oracle measures both, every millisecond of
the returned trajectory: the tool's distance from the segment and its rotation from the line's
orientation (forward kinematics), whether it ends at the goal (within the tolerance), and the
peak velocity, acceleration and jerk over the limits (ours by exact extrema; roboplan's by
finite differences of its 1 ms samples, as a controller would see them). The last column holds
ours against the shortest jerk-limited rest-to-rest motion between the same ends on any path
(Ruckig's, :mod:`planning.bench.ruckig_bound`): a lower bound no line can beat.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

import cpr_kin as ck
from cpr_kin.common.names import one_line
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from planning.bench.roboplan_lines import RoboplanLines
from planning.bench.ruckig_bound import ruckig_duration
from planning.cli.arguments import COUNT, SEED
from planning.errors import ToolLineBrokenError
from planning.pipeline.verification import Requirements
from planning.task import LineTolerance, ToolLine, plan_line
from planning.task.tool_line import LineGeometry

TOLERANCE = LineTolerance()
NAN = math.nan


@dataclass(frozen=True)
class Run:
    """One planner on one line, as the oracle measured it."""

    solved: bool
    planning_s: float
    duration_s: float = NAN
    deviation_m: float = NAN
    usage: tuple[float, float, float] = (NAN, NAN, NAN)
    """Peak velocity, acceleration and jerk over their limits."""
    bound_s: float = NAN
    """Ruckig's time-optimal jerk-limited duration between the same ends, rest to rest [s]."""


REQUIRED = Requirements(margin_m=0.0, step_m=0.01, self_margin_m=0.0)
"""The same requirement of both: no contact, with obstacles or the robot itself (roboplan keeps no margin)."""


def robot_spec(name: str) -> ck.RobotSpec:
    return ck.cpr_spec() if name == "cpr" else ck.RobotSpec(urdf=example_robot(name))


def draw_lines(
    name: str, robot: ck.Robot, world: ck.CollisionWorld, count: int, seed: int
) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` lines ``(q, offset [m])``: a start clear of the robot itself, a direction, a length."""
    rng = np.random.default_rng(seed)
    lines: list[tuple[np.ndarray, np.ndarray]] = []
    while len(lines) < count:
        q = rng.uniform(robot.limits.lower, robot.limits.upper)
        if not world.keeps_clearance(q[None], 0.0, 0.01)[0]:
            continue
        if name == "cpr":  # up or down, and along the arm's reach
            theta = q[list(robot.joint_names).index("theta1")]
            turn = rng.uniform(0.0, 2.0 * np.pi)
            direction = np.array([np.cos(turn) * np.cos(theta), np.cos(turn) * np.sin(theta), np.sin(turn)])
        else:
            direction = rng.normal(size=3)
            direction /= np.linalg.norm(direction)
        lines.append((q, rng.uniform(0.05, 0.20) * direction))
    return lines


def deviation(
    robot: ck.Robot, frame: str, line: LineGeometry, positions: np.ndarray
) -> tuple[float, float, bool]:
    """The oracle: largest distance [m] and angle [rad] from the line, and whether the end is the goal."""
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(frame)
    worst_m = worst_rad = 0.0
    shift = line.shift_m
    for q in positions:
        pin.framesForwardKinematics(model, data, q)
        pose = data.oMf[fid]
        sigma = float(
            np.clip((pose.translation - line.start.translation) @ shift / (shift @ shift), 0.0, 1.0)
        )
        worst_m = max(worst_m, float(np.linalg.norm(pose.translation - line.pose(sigma).translation)))
        worst_rad = max(
            worst_rad, float(np.linalg.norm(pin.log3(line.pose(sigma).rotation.T @ pose.rotation)))
        )
    end = data.oMf[fid]
    reached = (
        np.linalg.norm(end.translation - line.goal.translation) <= TOLERANCE.position_m
        and np.linalg.norm(pin.log3(line.goal.rotation.T @ end.rotation)) <= TOLERANCE.angle_rad
    )
    return worst_m, worst_rad, bool(reached)


def peer_usage(robot: ck.Robot, times: np.ndarray, positions: np.ndarray) -> tuple[float, float, float]:
    """Peak velocity, acceleration and jerk over the limits, by finite differences of the samples."""
    limits = (robot.limits.velocity, robot.limits.acceleration, robot.limits.jerk)
    values, usage = positions, []
    for limit in limits:
        values = np.diff(values, axis=0) / np.diff(times)[: len(values) - 1, None]
        usage.append(float(np.max(np.abs(values) / limit)) if len(values) else NAN)
    return usage[0], usage[1], usage[2]


@dataclass(frozen=True)
class Bench:
    """Both planners' runs on one robot's lines; ``peer_refused``: why roboplan could not load it."""

    ours: list[Run]
    theirs: list[Run]
    peer_refused: str = ""


def bench_robot(name: str, count: int, seed: int) -> Bench:
    """Ours and roboplan's runs on ``count`` lines of the robot ``name``, alternated line by line.

    A robot roboplan cannot load (0.7.0 refuses the Z1: a link and a joint sharing a frame
    name) leaves its lines unsolved by it, with its reason; ours are planned and counted.
    """
    spec = robot_spec(name)
    robot = spec.load()
    world = ck.CollisionWorld(robot, [])
    lines = draw_lines(name, robot, world, count, seed)
    peer: RoboplanLines | None = None
    refused = ""
    try:
        peer = RoboplanLines(spec, robot, lines[0][0], TOLERANCE)
    except Exception as exc:  # the peer cannot take this robot: ours stand, and why it could not
        refused = one_line(f"{type(exc).__name__}: {exc}", 200)
    ours, theirs = [], []
    for q, offset in lines:
        ours.append(our_run(robot, world, q, offset))
        theirs.append(Run(False, NAN) if peer is None else peer_run(world, peer, q, offset))
    return Bench(ours, theirs, refused)


def our_run(robot: ck.Robot, world: ck.CollisionWorld, q: np.ndarray, offset: np.ndarray) -> Run:
    """:func:`plan_line`, timed, and the oracle's measures of its trajectory."""
    started = time.perf_counter()
    try:
        motion = plan_line(world, q, ToolLine(by=tuple(offset), offset_frame="base"), REQUIRED)
    except ToolLineBrokenError:
        return Run(False, time.perf_counter() - started)
    elapsed = time.perf_counter() - started
    trajectory = motion.trajectory
    times = np.append(np.arange(trajectory.knots[0], trajectory.knots[-1], 1e-3), trajectory.knots[-1])
    distance, _, reached = deviation(robot, motion.frame, motion.geometry, trajectory(times))
    limits = (robot.limits.velocity, robot.limits.acceleration, robot.limits.jerk)
    v, a, j = (float(np.max(trajectory.extrema(r).peak / limit)) for r, limit in enumerate(limits, start=1))
    ends = trajectory(trajectory.knots[[0, -1]])
    bound_s = ruckig_duration(ends[0], ends[1], *limits)
    return Run(reached, elapsed, trajectory.duration, distance, (v, a, j), bound_s)


def peer_run(world: ck.CollisionWorld, peer: RoboplanLines, q: np.ndarray, offset: np.ndarray) -> Run:
    """The peer's line, timed, and the oracle's measures of its samples (clear of itself at each)."""
    robot = world.robot
    frame = robot.tcp_frame
    start = ck.frame_poses(robot, q, frame)
    goal = start.copy()
    goal[:3, 3] += offset
    found = peer.plan(q, start, goal, frame)
    if not found.success:
        return Run(False, found.planning_time_s)
    line = LineGeometry(pin.SE3(start[:3, :3], start[:3, 3]), pin.SE3(goal[:3, :3], goal[:3, 3]))
    distance, _, reached = deviation(robot, frame, line, found.positions)
    clear = bool(world.keeps_clearance(found.positions, 0.0, 0.0).all())
    solved = (
        clear and reached and distance <= 1.5 * TOLERANCE.position_m
    )  # its bound: a target, not a promise
    usage = peer_usage(robot, found.times, found.positions)
    return Run(solved, found.planning_time_s, float(found.times[-1]), distance, usage)


def median(values: list[float]) -> float:
    """The median, ``nan`` of nothing."""
    return statistics.median(values) if values else NAN


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--lines", type=COUNT, default=20)
    parser.add_argument("--seed", type=SEED, default=1)
    parser.add_argument(
        "--robots", nargs="+", default=["cpr", "panda", "ur5"], choices=["cpr", *EXAMPLE_ROBOTS]
    )
    args = parser.parse_args()
    refused: list[str] = []
    print(
        "| robot | lines | solved ours / roboplan | median planning [ms] ours / roboplan (ratio) "
        "| median duration [s] on both solved, ours / roboplan (ratio) | largest deviation sampled [mm] "
        "ours / roboplan | peak v, a, j over limit: ours / roboplan | ours / Ruckig's jerk-limited bound |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in args.robots:
        bench = bench_robot(name, args.lines, args.seed)
        ours, theirs = bench.ours, bench.theirs
        if bench.peer_refused:
            refused.append(f"roboplan could not load {name}: {bench.peer_refused}")
        both = [k for k in range(len(ours)) if ours[k].solved and theirs[k].solved]
        planning = [median([run.planning_s * 1e3 for run in side]) for side in (ours, theirs)]
        durations = [median([side[k].duration_s for k in both]) for side in (ours, theirs)]
        worst = [max((r.deviation_m * 1e3 for r in side if r.solved), default=NAN) for side in (ours, theirs)]
        peaks = [
            "/".join(f"{max((r.usage[i] for r in side if r.solved), default=NAN):.2f}" for i in range(3))
            for side in (ours, theirs)
        ]
        print(
            f"| {name} | {len(ours)} | {sum(r.solved for r in ours)} / {sum(r.solved for r in theirs)} "
            f"| {planning[0]:.1f} / {planning[1]:.1f} ({planning[0] / planning[1]:.1f}) "
            f"| {durations[0]:.3f} / {durations[1]:.3f} ({durations[0] / durations[1]:.2f}, n = {len(both)}) "
            f"| {worst[0]:.4f} / {worst[1]:.4f} | {peaks[0]} / {peaks[1]} "
            f"| {median([r.duration_s / r.bound_s for r in ours if r.solved]):.3f} |"
        )
    for reason in refused:
        print(f"\n{reason}")


if __name__ == "__main__":
    main()
