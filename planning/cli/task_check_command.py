"""``cpr-plan check`` and ``show`` of a task's trajectory file: its promises verified, its timeline."""

from __future__ import annotations

import argparse
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from cpr_kin.common.names import escaped
from planning.errors import PlanningError
from planning.io import json_layout
from planning.outcome import EXIT_NO_TRAJECTORY, EXIT_OK

if TYPE_CHECKING:
    from planning.io.scene_file import SceneFile
    from planning.io.trajectory_reader import TrajectoryFile


def check_task_file(read: SceneFile, document: TrajectoryFile, args: argparse.Namespace) -> int:
    """Verify a task's trajectory file against the scene file that holds the task; exit 3 when it fails.

    Raises:
        PlanningError: the trajectory follows a task and the scene holds none, or the other way
            round; joints that are not the robot's; an entry of the ``task`` list that is not one.
    """
    from planning.task import check_task

    if not read.task:
        raise PlanningError(
            f"{args.trajectory} follows a task of {len(document.task or [])} segments, but {args.scene} "
            "holds no task: check it against the scene file that holds the task (its 'task:')"
        )
    if document.task is None:
        raise PlanningError(
            f"{args.scene} holds a task of {len(read.task)} segments, but {args.trajectory} has no 'task' "
            "list: plan the scene with `cpr-plan plan`, which writes it"
        )
    robot = read.scene.robot_spec().load()
    if robot.joint_names != document.joint_names:
        raise PlanningError(
            f"trajectory joints {list(document.joint_names)} are not the robot's {list(robot.joint_names)}"
        )
    checked = check_task(read.scene, read.task, document.trajectory, document.task, robot)
    if args.json:
        record = {
            "status": "ok" if checked.accepted else "failed",
            "certified_min_clearance_m": checked.certified_min_clearance_m,
            "safety_margin_m": read.scene.safety_margin,
            "checks": checked.checks,
            "certified_steps_m": [None if v is None else v.check.step_m for v in checked.verifications],
            "problems": list(checked.problems),
            "segments": len(read.task),
        }
        print(json_layout.dumps(record))
    elif checked.problems:
        print(escaped(f"{args.trajectory}: FAILS {args.scene}:\n  " + "\n  ".join(checked.problems)))
    else:
        from planning.io.report import clearance_text  # numpy's: not at the command's start

        print(
            escaped(
                f"{args.trajectory}: verified against {args.scene}: a task of {len(read.task)} segments, "
                f"certified clearance {clearance_text(checked.certified_min_clearance_m)} >= "
                f"{read.scene.safety_margin} m over {checked.checks} checks with what the robot carries "
                "in each, every line within its tolerance at every instant, joints within range and limits, "
                "torques within effort limits, jerk continuous (coal's tolerance: 1e-6 of a distance)"
            )
        )
    return EXIT_OK if checked.accepted else EXIT_NO_TRAJECTORY


def timeline(entries: Sequence[Mapping[str, Any]]) -> str:
    """The task's segments, one line each: index, times [s], kind, and what it holds or carries."""
    lines = ["task:"]
    for index, entry in enumerate(entries):
        kind, t0, t1 = entry.get("kind"), entry.get("t0"), entry.get("t1")
        timed = isinstance(t0, int | float) and isinstance(t1, int | float)
        times = f"{t0:8.3f} -> {t1:8.3f} s" if timed else "?"
        what = ""
        if "object" in entry:
            what = f" '{entry['object']}' at {entry.get('frame')}"
        elif kind == "line":
            what = f" of {entry.get('frame')}, within {entry.get('tolerance')}"
        lines.append(f"  [{index}] {times}  {kind}{what}")
    return "\n".join(lines)
