"""The files a plan produces, rendered in memory.

:meth:`planning.io.publish.OutputFolder.publish` then publishes them as one set, or none.
"""

from __future__ import annotations

from planning.io.report import report_markdown
from planning.io.trajectory_io import plan_samples_csv, trajectory_json
from planning.pipeline.result import PlanResult


def plan_files(
    result: PlanResult, paper: bool = False, plots: bool = False, html: bool = False, timings: bool = False
) -> dict[str, str | bytes]:
    """``trajectory.json``, ``samples.csv`` and ``report.md``; the plots and ``viewer.html`` if asked."""
    files: dict[str, str | bytes] = {
        "trajectory.json": trajectory_json(result, timings=timings),
        "samples.csv": plan_samples_csv(result),
        "report.md": report_markdown(result, paper),
    }
    if plots:
        from planning.viz.artifacts import plot_files

        files.update(plot_files(result))
    if html:
        from planning.viz.artifacts import viewer_html

        files["viewer.html"] = viewer_html(
            result.problem.world, result.scene.safety_margin, result.trajectory, result.waypoints
        )
    return files
