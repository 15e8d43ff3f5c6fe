"""The numerical IK with and without its patience, on the example arms: success, time, the solution chosen.

    python scripts/bench_ik.py [--targets 40] [--seed 1]

For each arm, ``--targets`` seeded random poses and positions of its tool frame (the forward
kinematics of random configurations, so each is reachable), each solved from another random
configuration as the seed (a goal solved near its start), by :func:`cpr_kin.solve_ik` with
its default :class:`cpr_kin.IkSettings` and with ``patience`` equal to ``iterations`` (every
start runs all its steps, the rule before it). The two alternate target by target, warm, in
one process. It prints per arm: the targets each solves, the mean time per target [ms], the
targets where both choose the same configuration, where they differ the geometric mean of
the distance to the seed (new over old, in robot motion ``sum_j R_j |dq_j|``), and the time
to refuse a target out of reach: 5 m away, beyond
:func:`cpr_kin.kinematics.numerical_ik.tool_reach_m` (refused
before any start), and 10 % beyond the farthest of 20,000 random configurations' tool positions
but within that bound (every start runs).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import numpy as np

import cpr_kin as ck
from cpr_kin.certified.motion import path_weights
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from planning.cli.arguments import COUNT, SEED


@dataclasses.dataclass
class Tally:
    """One IK setting's figures on one arm."""

    solved: int = 0
    seconds: float = 0.0


def timed(
    robot: ck.Robot, target: ck.IkTarget, seed: np.ndarray, settings: ck.IkSettings, tally: Tally
) -> np.ndarray | None:
    """The solution (or ``None``), its time added to ``tally``."""
    started = time.perf_counter()
    try:
        q = ck.solve_ik(robot, target, seed, settings=settings)
        tally.solved += 1
    except ck.IkMissError:
        q = None
    tally.seconds += time.perf_counter() - started
    return q


def refusal_s(robot: ck.Robot, settings: ck.IkSettings, position: np.ndarray) -> float:
    """Seconds to refuse the tool ``position`` [m] (a target out of reach)."""
    started = time.perf_counter()
    try:
        ck.solve_ik(robot, ck.IkTarget(position), settings=settings)
    except ck.IkMissError:
        return time.perf_counter() - started
    raise SystemExit(f"{robot.tcp_frame} reached {position.round(3).tolist()} m, a target out of reach")


def beyond_sampled_reach(robot: ck.Robot, rng: np.random.Generator) -> np.ndarray:
    """A tool position 10 % beyond the farthest of 20,000 random configurations' [m]."""
    configurations = rng.uniform(robot.limits.lower, robot.limits.upper, (20_000, robot.nq))
    positions = ck.frame_poses(robot, configurations)[:, :3, 3]
    return np.asarray(1.1 * positions[np.argmax(np.linalg.norm(positions, axis=1))], dtype=float)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--targets", type=COUNT, default=40, help="targets per arm (default: 40)")
    parser.add_argument("--seed", type=SEED, default=1, help="seed of the draws (default: 1)")
    args = parser.parse_args()
    new = ck.IkSettings()
    old = dataclasses.replace(new, patience=new.iterations)
    print(
        f"{'arm':<8}{'solved new/old':>16}{'ms new/old':>16}{'ratio':>7}{'same':>6}"
        f"{'dist new/old':>14}{'refuse ms, 5 m':>16}{'refuse ms, near':>17}"
    )
    for name in sorted(EXAMPLE_ROBOTS):
        robot = ck.load_robot(example_robot(name))
        weights, lower, upper = path_weights(robot), robot.limits.lower, robot.limits.upper
        rng = np.random.default_rng(args.seed)
        tallies, same, ratios = {"new": Tally(), "old": Tally()}, 0, []
        for k in range(args.targets):
            wanted, seed = rng.uniform(lower, upper, (2, robot.nq))
            tool = ck.frame_poses(robot, wanted[None])[0]
            target = ck.IkTarget(tool[:3, 3], tool[:3, :3] if k % 2 else None)
            order = (("new", new), ("old", old)) if k % 2 else (("old", old), ("new", new))
            found = {label: timed(robot, target, seed, settings, tallies[label]) for label, settings in order}
            if found["new"] is None or found["old"] is None:
                continue
            if np.allclose(found["new"], found["old"], atol=1e-9):
                same += 1
            else:
                distance = {label: float(weights @ np.abs(q - seed)) for label, q in found.items()}
                ratios.append(distance["new"] / max(distance["old"], 1e-12))
        far, near = np.array([5.0, 0.0, 0.5]), beyond_sampled_reach(robot, rng)
        both = (("new", new), ("old", old))
        refuse_far = {label: refusal_s(robot, settings, far) for label, settings in both}
        refuse_near = {label: refusal_s(robot, settings, near) for label, settings in both}
        ms = {label: 1e3 * tally.seconds / args.targets for label, tally in tallies.items()}
        geo = f"{math.exp(float(np.mean(np.log(ratios)))):.3f}" if ratios else "-"
        print(
            f"{name:<8}{tallies['new'].solved:>9} / {tallies['old'].solved:<4}"
            f"{ms['new']:>9.1f} / {ms['old']:<5.1f}{ms['new'] / ms['old']:>6.2f}{same:>6}{geo:>14}"
            f"{1e3 * refuse_far['new']:>8.0f} / {1e3 * refuse_far['old']:<5.0f}"
            f"{1e3 * refuse_near['new']:>9.0f} / {1e3 * refuse_near['old']:<5.0f}"
        )


if __name__ == "__main__":
    main()
