"""Upright carries to a pose: the goal's IK solution chosen on the constraint, planned as a task plans it.

    python scripts/bench_carry_goals.py [--carries 20] [--seed 3] [--robots ur10 ur5 panda]
                                        [--against-nearest]

For each robot, ``--carries`` seeded carries: a start with the tool pointing down at a random
bearing, reach and height, its configuration the IK's from a random one (any branch, any turn
of the base), and a goal at the same height a bearing 0.8 to 2.5 rad further round either way,
given as a pose (tool down, yaw free) that the planner resolves
(:func:`planning.task.held_orientation.goal_on_constraint`: the nearest IK solution whose
straight joint path from the start bends onto the constraint). Each is planned by
:func:`planning.task.plan_task` (a warm library call) to the pose. Prints per robot: the
carries planned, their median planning time and duration, and those whose goal is not the
nearest IK solution. With ``--against-nearest``, those are planned to the nearest solution
too, given as joint values (what the goal was before the constraint chose it), and the table
compares both on them. A carry that fails ends when the planner gives up (its search on the
constraint: a minute or several), so that comparison takes long.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

import cpr_kin as ck
from cpr_kin.kinematics.ik_target import IkTarget
from cpr_kin.kinematics.numerical_ik import solve_ik
from cpr_kin.model.packages import example_robot
from planning.cli.arguments import COUNT, SEED
from planning.errors import NoSolutionError, PlanningError
from planning.io.scene_file import parse_scene_file
from planning.task import plan_task

DOWN_RPY = [math.pi, 0.0, 0.0]
DOWN = np.diag([1.0, -1.0, -1.0])  # the tool's z axis straight down
UPRIGHT = {"axes": ["x", "y"], "angle_rad": 0.0873}


@dataclass(frozen=True)
class Run:
    """One task planned: whether it was, in what time [s], how long [s] and where it ends."""

    solved: bool
    planning_s: float
    duration_s: float = math.nan
    end: np.ndarray | None = None


def draw(robot: ck.Robot, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, list[float]] | None:
    """A start, the goal's nearest IK solution and its position (module docstring); ``None``: a miss."""
    bearing, turn = rng.uniform(-math.pi, math.pi), rng.uniform(0.8, 2.5) * rng.choice([-1.0, 1.0])
    reach, height = rng.uniform(0.4, 0.7), rng.uniform(0.2, 0.45)
    start_xyz = np.array([reach * math.cos(bearing), reach * math.sin(bearing), height])
    goal_xyz = [reach * math.cos(bearing + turn), reach * math.sin(bearing + turn), height]
    try:
        start = solve_ik(
            robot, IkTarget(start_xyz, DOWN), seed_q=rng.uniform(robot.limits.lower, robot.limits.upper)
        )
        nearest = solve_ik(robot, IkTarget(np.array(goal_xyz), DOWN), seed_q=start)
    except ck.CprKinError:
        return None
    return start, nearest, goal_xyz


def planned(document: dict[str, Any], robot: ck.Robot) -> Run:
    """The task of ``document`` planned (:func:`planning.task.plan_task`), timed."""
    read = parse_scene_file(document, "carry")
    started = time.perf_counter()
    try:
        task = plan_task(read.scene, read.task, robot)
    except (NoSolutionError, PlanningError):
        return Run(False, time.perf_counter() - started)
    elapsed, trajectory = time.perf_counter() - started, task.trajectory
    return Run(task.accepted, elapsed, float(trajectory.duration), trajectory(trajectory.knots[-1]))


def median(values: list[float]) -> float:
    """The median, ``nan`` of nothing."""
    return statistics.median(values) if values else math.nan


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--carries", type=COUNT, default=20)
    parser.add_argument("--seed", type=SEED, default=3)
    parser.add_argument("--robots", nargs="+", default=["ur10", "ur5", "panda"])
    parser.add_argument("--against-nearest", action="store_true")
    args = parser.parse_args()
    print(
        "| robot | planned to the pose | median planning [s] | median duration [s] | goals off the "
        "nearest IK solution | of those planned: to the pose / to the nearest | their median planning [s] "
        "| their median duration [s], both planned |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in args.robots:
        robot = ck.load_robot(example_robot(name))
        rng = np.random.default_rng(args.seed)
        poses, moved = list[Run](), list[tuple[Run, Run]]()
        for _ in range(args.carries):
            while (carry := draw(robot, rng)) is None:
                pass
            start, nearest, goal_xyz = carry
            base = {"robot": name, "safety_margin": 0.02, "start": {"q": start.tolist()}}
            to_pose = planned(
                {
                    **base,
                    "task": [{"move": {"pose": {"xyz": goal_xyz, "rpy": DOWN_RPY}, "constraint": UPRIGHT}}],
                },
                robot,
            )
            poses.append(to_pose)
            if to_pose.end is not None and np.abs(to_pose.end - nearest).max() <= 1e-6:
                continue  # the nearest solution: the same plan
            if not args.against_nearest:
                moved.append((to_pose, Run(False, math.nan)))
                continue
            to_nearest = planned(
                {**base, "task": [{"move": {"q": nearest.tolist(), "constraint": UPRIGHT}}]}, robot
            )
            moved.append((to_pose, to_nearest))
        print(row(name, poses, moved, args.against_nearest), flush=True)


def row(name: str, poses: list[Run], moved: list[tuple[Run, Run]], against: bool) -> str:
    """The table's row of one robot: every carry to the pose; those whose goal moved, both ways."""
    solved = [r for r in poses if r.solved]
    cells = [
        name,
        f"{len(solved)} / {len(poses)}",
        f"{median([r.planning_s for r in poses]):.2f}",
        f"{median([r.duration_s for r in solved]):.2f}",
        str(len(moved)),
    ]
    if not against or not moved:
        return "| " + " | ".join([*cells, "-", "-", "-"]) + " |"
    pose_runs, nearest_runs = zip(*moved, strict=True)
    both = [(a, b) for a, b in moved if a.solved and b.solved]
    cells += [
        f"{sum(r.solved for r in pose_runs)} / {sum(r.solved for r in nearest_runs)}",
        " / ".join(f"{median([r.planning_s for r in side]):.2f}" for side in (pose_runs, nearest_runs)),
        " / ".join(f"{median([pair[k].duration_s for pair in both]):.2f}" for k in (0, 1)),
    ]
    return "| " + " | ".join(cells) + " |"


if __name__ == "__main__":
    main()
