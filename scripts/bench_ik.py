"""The numerical IK on the example arms: success, time, and how soon the robot reaches what it chose.

    python scripts/bench_ik.py [--targets 40] [--seed 1] [--robots panda pr2 tiago ...]

For each arm, ``--targets`` seeded random poses and positions of its tool frame (the forward
kinematics of random configurations, so each is reachable), each solved from another random
configuration as the seed (a goal solved near its start) by :func:`cpr_kin.solve_ik` with its
default :class:`cpr_kin.IkSettings`, warm, in one process. It prints per arm: the targets
solved, the mean time per target [ms], the median move time from the seed to the solution
chosen [s] (the slowest joint's rest-to-rest time under its velocity and acceleration limits,
which a straight joint motion takes at least), that time over the move time to the
configuration the target was made from (a solution the robot could have taken), median and
worst, and the time to refuse a target out of reach: 5 m away, beyond
:func:`cpr_kin.kinematics.numerical_ik.tool_reach_m` (refused before any start), and 10 %
beyond the farthest of 20,000 random configurations' tool positions but within that bound
(every start runs).

The arms are example-robot-data's (:data:`~cpr_kin.model.packages.EXAMPLE_ROBOTS`) and the arms
of its PR2 (the left one) and TIAGo, on their torso lifts (0.013 and 0.07 m/s, far slower than
their arms' joints): mobile manipulators'. The move times come from
:func:`planning.curves.ptp.trapezoid_time`, which checkouts before and after stop 125 both have,
so that two checkouts' figures compare.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

import numpy as np

import cpr_kin as ck
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot, example_robot_data_share
from planning.cli.arguments import COUNT, SEED
from planning.curves.ptp import trapezoid_time

ON_A_LIFT = {
    "pr2": ("pr2_description/urdf/pr2.urdf", "l_gripper_tool_frame"),
    "tiago": ("tiago_description/robots/tiago.urdf", "arm_tool_link"),
}
"""example-robot-data's mobile manipulators: each URDF and its arm's tool frame (the planned joints:
the torso lift, 0.013 and 0.07 m/s, and the arm's seven)."""
ARMS = (*sorted(EXAMPLE_ROBOTS), *ON_A_LIFT)


@dataclasses.dataclass
class Tally:
    """One arm's figures."""

    solved: int = 0
    seconds: float = 0.0
    moves_s: list[float] = dataclasses.field(default_factory=list)
    ratios: list[float] = dataclasses.field(default_factory=list)


def load(name: str) -> ck.Robot:
    """An arm of :data:`ARMS`."""
    if name not in ON_A_LIFT:
        return ck.load_robot(example_robot(name))
    share = example_robot_data_share()
    if share is None:
        raise SystemExit(f"bench_ik: the {name} needs example-robot-data (the 'robots' extra)")
    urdf, tcp = ON_A_LIFT[name]
    return ck.load_robot(Path(share) / "example-robot-data" / "robots" / urdf, tcp=tcp)


def move_time_s(robot: ck.Robot, change: np.ndarray) -> float:
    """The slowest joint's shortest rest-to-rest time over ``change`` [s]: trapezoids of ``v`` and ``a``."""
    return float(trapezoid_time(change, robot.limits.velocity, robot.limits.acceleration).max())


def refusal_s(robot: ck.Robot, position: np.ndarray) -> float:
    """Seconds to refuse the tool ``position`` [m] (a target out of reach)."""
    started = time.perf_counter()
    try:
        ck.solve_ik(robot, ck.IkTarget(position))
    except ck.IkMissError:
        return time.perf_counter() - started
    raise SystemExit(f"{robot.tcp_frame} reached {position.round(3).tolist()} m, a target out of reach")


def beyond_sampled_reach(robot: ck.Robot, rng: np.random.Generator) -> np.ndarray:
    """A tool position 10 % beyond the farthest of 20,000 random configurations' [m]."""
    configurations = rng.uniform(robot.limits.lower, robot.limits.upper, (20_000, robot.nq))
    positions = ck.frame_poses(robot, configurations)[:, :3, 3]
    return np.asarray(1.1 * positions[np.argmax(np.linalg.norm(positions, axis=1))], dtype=float)


def measured(robot: ck.Robot, targets: int, seed: int) -> Tally:
    """The arm's IK on ``targets`` seeded targets (module docstring)."""
    lower, upper = robot.limits.lower, robot.limits.upper
    rng = np.random.default_rng(seed)
    tally = Tally()
    for k in range(targets):
        wanted, start = rng.uniform(lower, upper, (2, robot.nq))
        tool = ck.frame_poses(robot, wanted[None])[0]
        target = ck.IkTarget(tool[:3, 3], tool[:3, :3] if k % 2 else None)
        started = time.perf_counter()
        try:
            q = ck.solve_ik(robot, target, start)
        except ck.IkMissError:
            continue
        finally:
            tally.seconds += time.perf_counter() - started
        tally.solved += 1
        chosen_s = move_time_s(robot, q - start)
        tally.moves_s.append(chosen_s)
        tally.ratios.append(chosen_s / max(move_time_s(robot, wanted - start), 1e-9))
    return tally


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--targets", type=COUNT, default=40, help="targets per arm (default: 40)")
    parser.add_argument("--seed", type=SEED, default=1, help="seed of the draws (default: 1)")
    parser.add_argument("--robots", nargs="+", choices=ARMS, default=list(ARMS), help="arms (default: all)")
    args = parser.parse_args()
    print(
        f"{'arm':<8}{'solved':>8}{'ms':>7}{'move s':>8}{'over drawn':>12}{'worst':>7}"
        f"{'refuse ms, 5 m':>16}{'refuse ms, near':>17}"
    )
    for name in args.robots:
        robot = load(name)
        tally = measured(robot, args.targets, args.seed)
        near = beyond_sampled_reach(robot, np.random.default_rng(args.seed))
        far_ms = 1e3 * refusal_s(robot, np.array([5.0, 0.0, 0.5]))
        near_ms = 1e3 * refusal_s(robot, near)
        moves, ratios = f"{'-':>8}", f"{'-':>19}"
        if tally.solved:
            moves = f"{statistics.median(tally.moves_s):8.3f}"
            ratios = f"{statistics.median(tally.ratios):12.3f}{max(tally.ratios):7.2f}"
        print(
            f"{name:<8}{tally.solved:>4} / {args.targets:<2}{1e3 * tally.seconds / args.targets:>6.1f}"
            f"{moves}{ratios}{far_ms:>16.0f}{near_ms:>17.0f}"
        )


if __name__ == "__main__":
    main()
