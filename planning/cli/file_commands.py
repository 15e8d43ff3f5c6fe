"""``cpr-plan check`` and ``cpr-plan show``: re-verify or display a trajectory file."""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import cpr_kin as ck  # lazy (lazy_loader): only the modules a command uses are imported
from planning.cli.failure import EXIT_INVALID, EXIT_NO_TRAJECTORY, EXIT_OK, CommandError
from planning.cli.plan_commands import load
from planning.errors import PlanningError


def cmd_check(args: argparse.Namespace) -> int:
    """Re-verify a trajectory file against a scene; exit 3 when it fails."""
    from planning.io.trajectory_reader import read_trajectory
    from planning.problem import build_problem
    from planning.verification import verify_trajectory

    scene = load(args.scene)
    try:
        document = read_trajectory(args.trajectory)
        problem = build_problem(scene)
    except (PlanningError, ck.CprKinError) as exc:
        raise CommandError(EXIT_INVALID, str(exc)) from None
    robot = problem.robot
    if document.joint_names != robot.joint_names:
        raise CommandError(
            EXIT_INVALID,
            f"trajectory joints {list(document.joint_names)} are not the robot's {list(robot.joint_names)}",
        )
    verification = verify_trajectory(
        problem.world,
        document.trajectory,
        scene.safety_margin,
        scene.planner.verify_step_m,
        (problem.q_start, problem.q_goal),
    )
    check, problems = verification.check, verification.problems
    if args.json:
        print(json.dumps(verification.to_record(), indent=1))
    elif problems:
        print(f"{args.trajectory}: FAILS {args.scene}:\n  " + "\n  ".join(problems))
    else:
        print(
            f"{args.trajectory}: verified against {args.scene}: "
            f"certified clearance {check.certified_min_m:.4f} m "
            f">= {scene.safety_margin} m over {len(check.times)} checks, joints within range and limits"
        )
    return EXIT_OK if not problems else EXIT_NO_TRAJECTORY


def cmd_show(args: argparse.Namespace) -> int:
    """Show a trajectory file in a live meshcat viewer, or write it as one HTML page."""
    from planning.io.publish import write_file
    from planning.io.scene_file import parse_scene
    from planning.io.trajectory_reader import read_trajectory
    from planning.viz import artifacts

    try:
        document = read_trajectory(args.trajectory)
        scene = parse_scene(document.scene, source=f"{args.trajectory} (scene)")
        recorded = Path(document.robot)
        if not recorded.is_file():
            print(
                f"cpr-plan show: note: the recorded URDF '{recorded}' is not here; using the bundled CPR",
                file=sys.stderr,
            )
        robot = ck.load_cpr(recorded if recorded.is_file() else None)
        world = ck.CollisionWorld(robot, scene.obstacles)
    except (PlanningError, ck.CprKinError) as exc:
        raise CommandError(EXIT_INVALID, str(exc)) from None
    if args.html is not None:
        html = artifacts.viewer_html(
            world, scene.safety_margin, document.trajectory, document.waypoints, args.collision
        )
        try:
            written = write_file(args.html, html)
        except PlanningError as exc:
            raise CommandError(EXIT_INVALID, str(exc)) from None
        except OSError as exc:
            raise CommandError(EXIT_INVALID, f"cannot write '{args.html}': {exc.strerror or exc}") from None
        print(f"wrote {written} (self-contained; open it in a browser)")
        return EXIT_OK
    from planning.viz.viewer import Viewer

    with Viewer(world, scene.safety_margin) as viewer:
        viewer.show_geometry(visual=not args.collision, collision=args.collision)
        viewer.show_plan(document.trajectory, document.waypoints)
        viewer.animate(document.trajectory)
        print(f"meshcat viewer at {viewer.url}  (127.0.0.1 only; Ctrl-C to stop)", flush=True)
        try:
            while True:
                time.sleep(3600)
        except KeyboardInterrupt:
            print("viewer stopped", flush=True)
    return EXIT_OK
