"""The files a plan produces, rendered in memory.

:func:`planning.io.trajectory_io.write_files` then writes them all at once, or none.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from planning.io.report import markdown_table, paper_rows
from planning.io.trajectory_io import samples_csv, trajectory_document
from planning.planner import PlanResult


def report_markdown(result: PlanResult, paper: bool = False) -> str:
    """``report.md``: the figures of the plan, its jerk extrema and waypoints (and the paper's)."""
    m = result.metrics
    names = result.joint_names
    rows = [
        ("duration", f"{m.duration:.3f} s"),
        ("certified min clearance", f"{m.min_clearance:.4f} m (margin {result.scene.safety_margin} m)"),
        ("PTP time t_sol (objective)", f"{m.t_sol:.3f} s"),
        ("fitness", f"{m.fitness:.4f}"),
        ("max node deviation", f"{m.max_node_deviation:.3g}"),
        (
            "peak velocity, acceleration, jerk / limit",
            ", ".join(f"{v:.2f}" for v in m.limit_utilisation.values()),
        ),
        ("evaluations", str(m.evaluations)),
        ("planning time", f"{m.planning_time_s:.3f} s"),
    ]
    lines = [
        f"# Plan: {result.scene.name}",
        "",
        f"Seed {result.scene.planner.seed}, fitness `{result.scene.planner.fitness}`, "
        f"{len(result.scene.obstacles)} obstacle(s). Files: `trajectory.json` (cpr-trajectory/1), "
        "`samples.csv` (every IPO period).",
        "",
        "| figure | value |",
        "|---|---|",
        *[f"| {a} | {b} |" for a, b in rows],
        "",
        "| joint | jerk min | jerk max |",
        "|---|---|---|",
        *[f"| {n} | {m.jerk_min[n]:.4g} | {m.jerk_max[n]:.4g} |" for n in names],
        "",
        "Waypoints (start, intermediate, goal):",
        "",
        *[f"- {np.round(w, 5).tolist()}" for w in result.waypoints],
        "",
    ]
    if paper:
        lines += ["## Beside the paper", "", markdown_table(paper_rows(result)), ""]
    return "\n".join(lines)


def plan_files(
    result: PlanResult, paper: bool = False, plots: bool = False, html: bool = False, timings: bool = False
) -> dict[str, str | bytes]:
    """``trajectory.json``, ``samples.csv`` and ``report.md``; the plots and ``viewer.html`` if asked."""
    files: dict[str, str | bytes] = {
        "trajectory.json": json.dumps(trajectory_document(result, timings=timings), indent=1) + "\n",
        "samples.csv": samples_csv(result.trajectory, result.joint_names, result.scene.planner.ipo),
        "report.md": report_markdown(result, paper),
    }
    if plots:
        from planning.viz.artifacts import plot_files

        files.update(plot_files(result))
    if html:
        from planning.viz.artifacts import viewer_html

        scene = result.scene
        files["viewer.html"] = viewer_html(
            result.robot, scene.obstacles, scene.safety_margin, result.trajectory, result.waypoints
        )
    return files


def summary(result: PlanResult) -> dict[str, Any]:
    """The figures of a plan as plain JSON types."""
    m = result.metrics
    return {
        "status": "ok",
        "scene": result.scene.name,
        "seed": result.scene.planner.seed,
        "fitness_kind": result.scene.planner.fitness,
        "duration_s": m.duration,
        "min_clearance_m": m.min_clearance,
        "safety_margin_m": result.scene.safety_margin,
        "max_node_deviation": m.max_node_deviation,
        "t_sol_s": m.t_sol,
        "fitness": m.fitness,
        "evaluations": m.evaluations,
        "planning_time_s": m.planning_time_s,
        "limit_utilisation": m.limit_utilisation,
    }
