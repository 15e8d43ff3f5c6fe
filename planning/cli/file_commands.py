"""``cpr-plan check``, ``show`` and ``export``: re-verify, display or convert a trajectory file."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

import cpr_kin as ck  # lazy (lazy_loader): only the modules a command uses are imported
from cpr_kin.common.names import escaped
from planning.cli.plan_commands import load
from planning.errors import PlanningError
from planning.io import json_layout
from planning.outcome import EXIT_NO_TRAJECTORY, EXIT_OK

if TYPE_CHECKING:
    from planning.io.trajectory_reader import TrajectoryFile
    from planning.pipeline.scene import Scene


def cmd_check(args: argparse.Namespace) -> int:
    """Re-verify a trajectory file against a scene; exit 3 when it fails."""
    from planning.io.report import clearance_text
    from planning.io.trajectory_reader import read_trajectory
    from planning.pipeline.problem import build_problem
    from planning.pipeline.verification import verify_for_scene

    read = load(args.scene)
    document = read_trajectory(args.trajectory)
    if read.task or document.task is not None:
        from planning.cli.task_check_command import check_task_file

        return check_task_file(read, document, args)
    scene = read.scene
    problem = build_problem(scene)
    verification = verify_for_scene(
        problem, document.trajectory, document.joint_names, document.certified_step_m
    )
    check, problems = verification.check, verification.problems
    if args.json:
        print(json_layout.dumps(verification.to_record()))
    elif problems:
        print(escaped(f"{args.trajectory}: FAILS {args.scene}:\n  " + "\n  ".join(problems)))
    else:
        exact = len(problem.robot.exact_meshes)
        model = (
            f"; on the exact meshes of {exact} links, the other shapes within 1 mm of theirs" if exact else ""
        )
        print(
            escaped(
                f"{args.trajectory}: verified against {args.scene}: "
                f"certified clearance {clearance_text(check.certified_min_m)} "
                f">= {scene.safety_margin} m over {len(check.times)} checks "
                f"(at most {check.step_m * 1000:g} mm of robot motion apart), joints within range and limits"
                f"{', torques within effort limits' if problem.dynamics.limited else ''}"
                f"{model} (coal's tolerance: 1e-6 of a distance)"
            )
        )
    return EXIT_OK if not problems else EXIT_NO_TRAJECTORY


def shown_robot(document: TrajectoryFile, scene: Scene, urdf: Path | None) -> ck.Robot:
    """The robot to draw: ``urdf`` if given, else the robot the trajectory file records.

    The file's scene section records the robot entry (URDF, SRDF, meshes' folders, planned
    joints, tool) of a robot other than the default (read as a scene file reads it); the
    file's ``robot`` key the URDF that planned, which decides where the scene section names
    none (a robot given to ``plan`` loaded).

    Raises:
        PlanningError: the recorded robot's files are not on this machine (and no ``urdf`` given).
    """
    from planning.io.robot_entry import BUNDLED, default_robot, robot_spec_of

    if urdf is not None:  # a path, or a name (the bundled robot's, an example arm's)
        return robot_spec_of(str(urdf), Path.cwd()).load()
    spec = scene.robot_spec()
    if spec == default_robot() and document.robot not in (BUNDLED, str(spec.urdf)):
        spec = ck.robot_spec(Path(document.robot))
    if not Path(spec.urdf).is_file():
        raise PlanningError(
            f"the trajectory's robot URDF '{spec.urdf}' is not on this machine; "
            f"pass the robot with --urdf PATH (the bundled CPR: --urdf {BUNDLED})"
        )
    return spec.load()


def cmd_show(args: argparse.Namespace) -> int:
    """Show a trajectory file in a live meshcat viewer, or write it as one HTML page."""
    from planning.cli.task_check_command import timeline
    from planning.curves.continuity import discontinuity
    from planning.io.output_paths import check_not_inputs
    from planning.io.publish import write_file
    from planning.io.scene_file import parse_scene_file
    from planning.io.trajectory_reader import read_trajectory
    from planning.task.holding import untaken
    from planning.viz import artifacts
    from planning.viz.carried_objects import carried_spans, recorded_scenes
    from planning.viz.measured_clearance import sampled_clearance

    if args.html is not None:
        check_not_inputs([args.html], {"trajectory file": args.trajectory, "URDF": args.urdf})
    document = read_trajectory(args.trajectory)
    jump = discontinuity(document.trajectory, document.joint_names)
    if jump is not None:  # shown all the same: seeing it is what show is for
        print(escaped(f"warning: {args.trajectory} {jump}; `cpr-plan check` fails it"), file=sys.stderr)
    read = parse_scene_file(document.scene, source=f"{args.trajectory} (scene)")
    scene, changes, measured = read.scene, [], None
    base = shown_robot(document, scene, args.urdf)
    if base.joint_names != document.joint_names:
        raise PlanningError(
            f"trajectory joints {list(document.joint_names)} are not the robot's {list(base.joint_names)}"
        )
    if document.task is not None:
        print(escaped(timeline(document.task)), flush=True)
        scenes = recorded_scenes(scene, base, document.trajectory, read.task, document.task)
        changes = [(t, after.payload) for t, after in scenes]
        start = (float(document.trajectory.knots[0]), scene)
        measured = sampled_clearance(base, document.trajectory, [start, *scenes])  # each in its world
    carried = carried_spans(scene.payload, changes, float(document.trajectory.knots[-1]))
    robot = ck.carrying(base, scene.payload)  # its shape drawn too
    world = ck.CollisionWorld(robot, untaken(scene.obstacles, (p for _, p in changes)))
    if args.html is not None:
        html = artifacts.viewer_html(
            world,
            scene.safety_margin,
            document.trajectory,
            document.waypoints,
            args.collision,
            carried,
            measured=measured,
        )
        written = write_file(args.html, html)
        print(escaped(f"wrote {written} (self-contained; open it in a browser)"))
        return EXIT_OK
    from planning.viz.viewer import Viewer

    with Viewer(world, scene.safety_margin) as viewer:
        viewer.show_geometry(visual=not args.collision, collision=args.collision)
        viewer.show_carried(document.trajectory, carried)
        viewer.show_plan(document.trajectory, document.waypoints, measured=measured)
        viewer.animate(document.trajectory)
        try:  # from the line on, Ctrl-C is the way to stop: even one that strikes as it is written
            print(f"meshcat viewer at {viewer.url}  (127.0.0.1 only; Ctrl-C to stop)", flush=True)
            while True:
                time.sleep(3600)
        except KeyboardInterrupt:
            print("viewer stopped", flush=True)
    return EXIT_OK


EXPORTERS = {"joint-trajectory": "ROS trajectory_msgs/JointTrajectory (YAML or JSON by the file name)"}
"""The formats ``export`` writes, with what each is."""


def cmd_export(args: argparse.Namespace) -> int:
    """Write a trajectory file in another format (:data:`EXPORTERS`).

    The file is read as ``check`` reads it, and a trajectory that jumps at a knot is refused:
    a controller would be sent the jump.
    """
    from planning.io.joint_trajectory import sample_times, write_joint_trajectory
    from planning.io.output_paths import check_not_inputs
    from planning.io.trajectory_reader import read_trajectory, require_continuous

    check_not_inputs([args.out], {"trajectory file": args.trajectory})
    document = require_continuous(read_trajectory(args.trajectory), f"trajectory file '{args.trajectory}'")
    points = len(sample_times(document.trajectory, args.rate))
    written = write_joint_trajectory(document.trajectory, document.joint_names, args.out, args.rate)
    print(
        escaped(f"wrote {written}: {points} points of {len(document.joint_names)} joints at {args.rate:g} Hz")
    )
    return EXIT_OK
