"""Writing the files users exchange: ``cpr-trajectory/1`` JSON and CSV samples.

The trajectory file follows docs/formats.md; the samples are position, velocity,
acceleration and jerk every IPO period. Each file is written atomically
(:func:`planning.io.publish.write_file`); a plan's whole set is published by
:class:`planning.io.publish.OutputFolder`. Reading a trajectory file back is
:mod:`planning.io.trajectory_reader`'s.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planning.curves.trajectory import DERIVATIVE_NAMES, Trajectory
from planning.io.file_formats import TRAJECTORY
from planning.io.json_layout import dumps
from planning.io.publish import write_file
from planning.validation import instance_of

if TYPE_CHECKING:  # types only: writing files needs neither the planner nor the robot
    import cpr_kin as ck
    from planning.pipeline.result import PlanResult

FloatArray = NDArray[np.float64]


def trajectory_document(result: PlanResult, timings: bool = False) -> dict[str, Any]:
    """The ``cpr-trajectory/1`` document of a plan, as plain JSON types.

    Wall times (``planning_time_s``, ``optimiser_time_s``) are ``null`` unless ``timings``:
    the same scene and seed then give the same file, byte for byte.
    """
    from planning.io.report import plan_record
    from planning.io.scene_file import scene_to_dict

    trajectory = result.trajectory
    segments = [
        {"t0": float(t0), "t1": float(t1), "coeffs": trajectory.coefficients[i].tolist()}
        for i, (t0, t1) in enumerate(zip(trajectory.knots[:-1], trajectory.knots[1:], strict=True))
    ]
    return {
        "format": TRAJECTORY,
        "joint_names": list(result.joint_names),
        "robot": str(result.robot.urdf_path),
        "srdf": None if result.robot.srdf_path is None else str(result.robot.srdf_path),
        "scene": scene_to_dict(result.scene),
        "waypoints": result.waypoints.tolist(),
        "knots": trajectory.knots.tolist(),
        "segments": segments,
        "metrics": plan_record(result, timings),
    }


def trajectory_json(result: PlanResult, timings: bool = False) -> str:
    """The text of the plan's ``cpr-trajectory/1`` file (see :func:`trajectory_document`).

    Laid out by :func:`planning.io.json_layout.dumps`: a waypoint, a knot vector or a row of
    a segment's coefficients per line.
    """
    return dumps(trajectory_document(result, timings)) + "\n"


def write_trajectory(result: PlanResult, path: str | Path, timings: bool = False) -> None:
    """Write the plan as a ``cpr-trajectory/1`` JSON file, atomically (see :func:`trajectory_json`).

    Raises:
        PlanningError: ``result`` is no :class:`~planning.pipeline.result.PlanResult`.
    """
    _a_plan(result)
    write_file(Path(path), trajectory_json(result, timings))


def samples_csv(
    trajectory: Trajectory, joint_names: tuple[str, ...], period: float, limits: ck.JointLimits | None = None
) -> str:
    """CSV text of position, velocity, acceleration and jerk every ``period`` seconds.

    With ``limits``, three more columns: the largest ``|velocity|``, ``|acceleration|`` and
    ``|jerk|`` over the limit among the joints at each sample (:mod:`planning.utilisation`).
    """
    times = np.append(np.arange(trajectory.knots[0], trajectory.knots[-1], period), trajectory.knots[-1])
    columns = [trajectory(times, r) for r in range(4)]
    header = ["t"]
    for r in range(4):
        suffix = "" if r == 0 else f"_{DERIVATIVE_NAMES[r]}"
        header += [f"{name}{suffix}" for name in joint_names]
    if limits is not None:
        from planning.utilisation import ORDERS, limit_usage

        header += [f"{order}_usage" for order in ORDERS]
        columns.append(limit_usage(trajectory, limits, times).usage)
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(header)
    # numbers need no quoting: one %-format per row is several times faster than csv's writer
    row = ",".join(["%.6f", *["%.12g"] * (len(header) - 1)]) + "\n"
    values = np.column_stack([times, *columns]).tolist()
    buffer.write("".join([row % tuple(v) for v in values]))
    return buffer.getvalue()


def write_samples(result: PlanResult, path: str | Path) -> None:
    """Write the trajectory sampled at the planner's IPO period as CSV, atomically.

    Raises:
        PlanningError: ``result`` is no :class:`~planning.pipeline.result.PlanResult`.
    """
    _a_plan(result)
    write_file(Path(path), plan_samples_csv(result))


def _a_plan(result: Any) -> None:
    """Refuse what is not a plan's result (``None``, a task's motion), naming where one comes from."""
    from planning.pipeline.result import PlanResult  # the pipeline's, loaded by whoever planned

    instance_of("result", result, PlanResult, "planning.PlanResult (plan(scene))")


def plan_samples_csv(result: PlanResult) -> str:
    """A plan's ``samples.csv``: every IPO period, with the usage of the robot's limits."""
    return samples_csv(
        result.trajectory, result.joint_names, result.scene.planner.ipo, result.problem.robot.limits
    )
