"""The files a planned task produces: its ``cpr-trajectory/1`` file with the ``task`` list, samples, report.

The trajectory file is a plan's (docs/formats.md) with two differences: its scene section
holds the task (``task:`` where a plan's has ``goal:``), and a top-level ``task`` list says
what each segment promised (:func:`~planning.task.task_record.task_record`), which
``cpr-plan check`` verifies. Its ``waypoints`` are the junctions: the start and where each
segment ends.
"""

from __future__ import annotations

from typing import Any

from planning.io.file_formats import TRAJECTORY
from planning.io.json_layout import dumps
from planning.io.report import clearance_text, markdown_table
from planning.io.scene_file import scene_to_dict
from planning.io.trajectory_io import samples_csv
from planning.task.task_plan import TaskMotion
from planning.task.task_record import task_record


def task_metrics(task: TaskMotion, planning_time_s: float | None = None) -> dict[str, Any]:
    """The trajectory file's ``metrics`` of a task: duration [s], certified clearance [m], verdict."""
    return {
        "duration": task.trajectory.duration,
        "min_clearance": task.certified_min_clearance_m,
        "accepted": task.accepted,
        "segments": len(task.segments),
        "planning_time_s": planning_time_s,
        "seed": task.scene.planner.seed,
    }


def task_document(task: TaskMotion, planning_time_s: float | None = None) -> dict[str, Any]:
    """The ``cpr-trajectory/1`` document of a task, as plain JSON types (module docstring).

    ``planning_time_s`` is recorded if given (``None``: the same task gives the same file).
    """
    trajectory, robot = task.trajectory, task.world.robot
    return {
        "format": TRAJECTORY,
        "joint_names": list(robot.joint_names),
        "robot": str(robot.urdf_path),
        "srdf": None if robot.srdf_path is None else str(robot.srdf_path),
        "scene": scene_to_dict(task.scene, task.task),
        "task": task_record(task),
        "waypoints": task.junctions.tolist(),
        "knots": trajectory.knots.tolist(),
        "segments": [
            {"t0": float(t0), "t1": float(t1), "coeffs": trajectory.coefficients[i].tolist()}
            for i, (t0, t1) in enumerate(zip(trajectory.knots[:-1], trajectory.knots[1:], strict=True))
        ],
        "metrics": task_metrics(task, planning_time_s),
    }


def task_files(task: TaskMotion, planning_time_s: float | None = None) -> dict[str, str | bytes]:
    """``trajectory.json``, ``samples.csv`` (every IPO period, with the limits' usage) and ``report.md``."""
    robot = task.world.robot
    return {
        "trajectory.json": dumps(task_document(task, planning_time_s)) + "\n",
        "samples.csv": samples_csv(task.trajectory, robot.joint_names, task.scene.planner.ipo, robot.limits),
        "report.md": task_report_markdown(task),
    }


def task_summary_line(task: TaskMotion, planning_time_s: float) -> str:
    """The CLI's one-line summary of a planned task."""
    kinds = ", ".join(s.kind for s in task.segments)
    return (
        f"{task.scene.name}: verified task of {len(task.segments)} segments ({kinds}), "
        f"{task.trajectory.duration:.3f} s, "
        f"certified clearance {clearance_text(task.certified_min_clearance_m)} "
        f"(margin {task.scene.safety_margin} m), planned in {planning_time_s:.3f} s"
    )


def task_summary(task: TaskMotion, planning_time_s: float) -> dict[str, Any]:
    """The CLI's JSON summary of a planned task: its metrics and its record."""
    return {
        "status": "ok",
        "scene": task.scene.name,
        "safety_margin": task.scene.safety_margin,
        **task_metrics(task, planning_time_s),
        "task": task_record(task),
    }


def task_report_markdown(task: TaskMotion) -> str:
    """``report.md`` of a task: each segment's times, clearance and line deviation, then the whole."""
    rows = []
    for index, segment in enumerate(task.segments):
        verified = segment.verification
        clearance = "-"
        if verified is not None:  # the column's unit is in its header
            clearance = clearance_text(verified.check.certified_min_m).removesuffix(" m")
        line = segment.line
        deviation = (
            "-"
            if line is None
            else f"{line.deviation.position_m * 1e3:.3f} mm, {line.deviation.angle_rad * 1e3:.3f} mrad"
        )
        what = "" if segment.payload is None else f" '{segment.payload.name}'"
        if segment.held is not None:
            held = segment.held
            what = (
                f", {list(held.constraint.axes)} held within {held.constraint.angle_rad:.4g} rad "
                f"(certified {held.deviation.angle_rad:.4g})"
            )
        rows.append(
            (
                str(index),
                segment.kind + what,
                f"{segment.t0:.3f}",
                f"{segment.t1:.3f}",
                clearance,
                deviation,
            )
        )
    headers = ("segment", "kind", "t0 [s]", "t1 [s]", "certified clearance [m]", "off its line (certified)")
    verdict = "verified" if task.accepted else "FAILS: " + "; ".join(task.problems)
    lines = [
        f"# Task: {task.scene.name}",
        "",
        f"{len(task.segments)} segments in one trajectory of {task.trajectory.duration:.3f} s, {verdict}; "
        f"certified clearance {clearance_text(task.certified_min_clearance_m)} "
        f"(margin {task.scene.safety_margin} m); "
        "jerk continuous at every knot, at rest at its ends, waits, attaches and detaches, and at a "
        "junction where a stop is sooner than passing it.",
        "",
        markdown_table(rows, headers),
        "",
    ]
    return "\n".join(lines)
