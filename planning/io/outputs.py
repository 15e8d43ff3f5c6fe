"""The files a plan produces, rendered in memory.

:meth:`planning.io.publish.OutputFolder.publish` then publishes them as one set, or none.
"""

from __future__ import annotations

from planning.io.report import report_markdown
from planning.io.trajectory_io import plan_samples_csv, trajectory_json
from planning.pipeline.result import PlanResult


def plan_files(result: PlanResult, paper: bool = False, timings: bool = False) -> dict[str, str | bytes]:
    """``trajectory.json``, ``samples.csv`` and ``report.md``.

    The plots and ``viewer.html`` are drawn by :func:`planning.viz.artifacts.drawn_files`, which
    the command line adds when asked: files are written here, drawings made there.
    """
    return {
        "trajectory.json": trajectory_json(result, timings=timings),
        "samples.csv": plan_samples_csv(result),
        "report.md": report_markdown(result, paper),
    }
