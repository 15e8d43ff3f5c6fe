"""The paper case (DESIGN.md section 4), as far as the project goes today.

Loads the CPR, prints its joints and limits, solves the inverse kinematics of the paper's
start and goal TCP points, checks them against forward kinematics, and reports their
clearance to the paper's crate, then certifies (or refutes) the direct constant-height
swing between them with the continuous check. The firefly planner replaces the last step
once it exists.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import cpr_kin as ck

PAPER_START_TCP = (0.5, 0.45, 0.25)
PAPER_GOAL_TCP = (-0.5, 0.45, 0.25)
PAPER_CRATE = ck.Obstacle.box(size=(0.3, 0.3, 0.3), xyz=(0.0, 0.6, 0.15), name="crate")
PAPER_MARGIN_M = 0.1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--urdf", default=None, help="URDF of the CPR (default: the bundled one)")
    args = parser.parse_args(argv)
    try:
        robot = ck.load_cpr(args.urdf)
    except ck.CprKinError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2

    print(f"CPR loaded from {robot.urdf_path}")
    print(f"{'joint':8s} {'unit':4s} {'lower':>7s} {'upper':>7s} {'v max':>6s} {'a max':>6s} {'j max':>6s}")
    lim = robot.limits
    for i, name in enumerate(robot.joint_names):
        print(
            f"{name:8s} {robot.joint_unit(name):4s} {lim.lower[i]:7.2f} {lim.upper[i]:7.2f} "
            f"{lim.velocity[i]:6.2f} {lim.acceleration[i]:6.2f} {lim.jerk[i]:6.1f}"
        )

    world = ck.CollisionWorld(robot, [PAPER_CRATE])
    print(f"\nscene: crate 0.3 m cube at (0, 0.6, 0.15), safety margin {PAPER_MARGIN_M} m")
    configurations = {}
    for label, tcp in (("start", PAPER_START_TCP), ("goal", PAPER_GOAL_TCP)):
        q = ck.tcp_ik(robot, tcp)
        configurations[label] = q
        error = np.linalg.norm(ck.frame_positions(robot, q) - np.asarray(tcp))
        clearance = world.clearance(q)
        closest = clearance.closest
        assert closest is not None  # the scene has an obstacle
        verdict = "clear" if clearance.min_clearance_m >= PAPER_MARGIN_M else "VIOLATES the margin"
        groups = clearance.group_clearance_m
        print(
            f"{label:5s} tcp {tcp} -> q = {np.array2string(q, precision=4)}  (FK error {error:.1e} m)\n"
            f"      clearance effector {groups['effector']:.3f} m, links {groups['links']:.3f} m, "
            f"closest {closest.robot_geometry}-{closest.obstacle}: {verdict}"
        )

    check = ck.check_segment(world, configurations["start"], configurations["goal"], PAPER_MARGIN_M)
    print(
        f"\ndirect constant-height swing: certified clearance {check.certified_min_m:.3f} m "
        f"({len(check.times)} checks, <= {check.step_m * 1000:.0f} mm robot motion apart): "
        + ("accepted" if check.accepted else f"rejected, {check.worst_pair} in group '{check.worst_group}'")
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
