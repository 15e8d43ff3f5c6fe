"""A task's junctions passed where that is sooner, against a stop at each, on seeded tasks of several arms.

    python scripts/bench_junctions.py [--tasks 10] [--seed 0] [--robots cpr panda ur5]

For each robot, ``--tasks`` seeded tasks among no obstacles, each of two kinds: three free
motions in joint space (goals drawn within the joint ranges, 1 cm clear of the robot itself),
and a free motion, a tool line of 5 cm straight up in the base frame, then a free motion. Each
task is planned twice, warm, in one process: as given (the robot passes a junction where that
is sooner, :mod:`planning.task.task_timing`) and with a wait of 1 ms between its motions, so
that it stops at every junction (the oracle: what the task may take at most). A task either
refuses (a line that breaks, a goal it cannot reach) is drawn again.

Prints per robot and kind: the tasks planned, the median durations of both (the waits taken
out), the task's over the stops' (median and largest: at most 1 where the rule holds), the
junctions passed without stopping, and the median planning time. Run with another checkout
first on the path (``PYTHONPATH=DIR``) to measure its code on the same tasks.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

import cpr_kin as ck
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from planning.cli.arguments import COUNT, SEED
from planning.errors import NoSolutionError, PlanningError
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.task import Move, ToolLine, Wait, plan_task
from planning.task.segments import Segment

WAIT_S = 1e-3
"""The wait that makes the robot stop at a junction [s]."""
LINE_M = (0.0, 0.0, 0.05)
"""The tool line of the second kind of task: 5 cm straight up in the base frame [m]."""
PASSED_RAD_S = 1e-6
"""A junction where some joint moves faster than this [rad/s or m/s] is passed without stopping."""


def robot_spec(name: str) -> ck.RobotSpec:
    return ck.cpr_spec() if name == "cpr" else ck.RobotSpec(urdf=example_robot(name))


@dataclass(frozen=True)
class Pair:
    """One task planned as given and with a stop at every junction."""

    duration_s: float
    stopping_s: float
    """The stopping task's duration less its waits [s]."""
    passed: int
    junctions: int
    planning_s: float


def clear_configuration(robot: ck.Robot, world: ck.CollisionWorld, rng: np.random.Generator) -> Target:
    """A configuration drawn within the joint ranges, 1 cm clear of the robot itself."""
    while True:
        q = rng.uniform(robot.limits.lower, robot.limits.upper)
        if world.keeps_clearance(q[None], 0.0, 0.01)[0]:
            return Target(q=tuple(q.tolist()))


def with_stops(segments: list[Segment]) -> list[Segment]:
    """``segments`` with a wait of :data:`WAIT_S` between two that move."""
    stopping: list[Segment] = []
    for segment in segments:
        if stopping and not isinstance(segment, Wait) and not isinstance(stopping[-1], Wait):
            stopping.append(Wait(WAIT_S))
        stopping.append(segment)
    return stopping


def planned(scene: Scene, robot: ck.Robot, segments: list[Segment]) -> Pair | None:
    """``segments`` planned as given and with stops; ``None`` where either refuses."""
    try:
        started = time.perf_counter()
        task = plan_task(scene, segments, robot)
        planning_s = time.perf_counter() - started
        stopping = plan_task(scene, with_stops(segments), robot)
    except (PlanningError, NoSolutionError, ck.CprKinError):
        return None  # a line that breaks, a goal it cannot reach: drawn again
    if not (task.accepted and stopping.accepted):
        return None
    waits = len(stopping.segments) - len(task.segments)
    junctions = [s.t1 for s in task.segments[:-1]]
    speeds = np.abs(task.trajectory(np.array(junctions), 1)).max(axis=1) if junctions else np.empty(0)
    return Pair(
        duration_s=task.trajectory.duration,
        stopping_s=stopping.trajectory.duration - waits * WAIT_S,
        passed=int(np.count_nonzero(speeds > PASSED_RAD_S)),
        junctions=len(junctions),
        planning_s=planning_s,
    )


def three_moves(draw: Callable[[], Target]) -> list[Segment]:
    return [Move(draw()), Move(draw()), Move(draw())]


def move_line_move(draw: Callable[[], Target]) -> list[Segment]:
    return [Move(draw()), ToolLine(by=LINE_M, offset_frame="base"), Move(draw())]


KINDS: dict[str, Callable[[Callable[[], Target]], list[Segment]]] = {
    "three moves": three_moves,
    "move, line up, move": move_line_move,
}


def bench(name: str, count: int, seed: int) -> dict[str, list[Pair]]:
    """``count`` planned tasks of each kind on robot ``name``."""
    robot = ck.shared_robot(robot_spec(name))
    world = ck.CollisionWorld(robot, [])
    rng = np.random.default_rng(seed)
    found: dict[str, list[Pair]] = {}
    for kind, make in KINDS.items():
        pairs: list[Pair] = []
        for _ in range(20 * count):
            if len(pairs) == count:
                break
            start = clear_configuration(robot, world, rng)
            scene = Scene(robot=robot_spec(name), start=start, goal=start, obstacles=(), duration=None)
            pair = planned(scene, robot, make(lambda: clear_configuration(robot, world, rng)))
            if pair is not None:
                pairs.append(pair)
        found[kind] = pairs
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=COUNT, default=10, help="planned tasks of each kind per robot")
    parser.add_argument("--seed", type=SEED, default=0)
    parser.add_argument(
        "--robots",
        nargs="+",
        default=["cpr", "panda", "ur5"],
        choices=["cpr", *EXAMPLE_ROBOTS],
        metavar="ROBOT",
        help=f"robots to run: cpr or an example-robot-data arm ({', '.join(EXAMPLE_ROBOTS)})",
    )
    args = parser.parse_args()
    print(f"tasks among no obstacles, {args.tasks} of each kind per robot, seed {args.seed}, warm\n")
    print(
        "| robot | task | planned | duration, median [s] | stopping at every junction [s] | "
        "task / stopping, median | largest | junctions passed | planning, median [s] |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for name in args.robots:
        for kind, pairs in bench(name, args.tasks, args.seed).items():
            if not pairs:
                print(f"| {name} | {kind} | 0 | - | - | - | - | - | - |")
                continue
            ratios = [p.duration_s / p.stopping_s for p in pairs]
            passed = sum(p.passed for p in pairs)
            junctions = sum(p.junctions for p in pairs)
            print(
                f"| {name} | {kind} | {len(pairs)} | {statistics.median(p.duration_s for p in pairs):.3f} | "
                f"{statistics.median(p.stopping_s for p in pairs):.3f} | {statistics.median(ratios):.3f} | "
                f"{max(ratios):.3f} | {passed} of {junctions} | "
                f"{statistics.median(p.planning_s for p in pairs):.3f} |"
            )


if __name__ == "__main__":
    main()
