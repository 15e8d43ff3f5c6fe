"""Reading a ``cpr-trajectory/1`` file (docs/formats.md) that anyone may have written.

A file is read only if it is one: a bounded JSON document whose keys have the documented
types (pydantic, with field paths in the messages), finite numbers, one segment per knot
interval whose own ``t0`` and ``t1`` are those knots, eight coefficients per joint, and
values of a sane size. Anything else is a :class:`TrajectoryFileError` (the CLI's exit 2)
naming the key or the segment. Whether the trajectory is continuous (C3) at its knots and
keeps the margin is then for :func:`planning.pipeline.verification.verify_trajectory` (exit 3).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from cpr_kin.common.names import repeated
from cpr_kin.common.user_files import UserFileError, read_bytes
from planning.curves.continuity import discontinuity
from planning.curves.hermite import ORDER
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.io.file_formats import TrajectoryFormat
from planning.pipeline.scene import DURATION_RANGE_S
from planning.pipeline.settings import recorded_step_m

FloatArray = NDArray[np.float64]

MAX_TRAJECTORY_BYTES = 50_000_000
"""Largest trajectory file [bytes] (a plan writes about 20 kB)."""
MAX_SEGMENTS = 100_000
"""Most segments of a trajectory."""
MIN_SEGMENT_S = 1e-6
"""Shortest segment [s]: below it the local powers of time lose their digits."""
MAX_TASK_ENTRIES = 1000
"""Most entries of a trajectory file's ``task`` list."""
MAX_POSITION = 1e6
"""Largest |position| a segment's coefficients may reach, ``sum_k |a_k| h^k`` [rad or m]."""


class TrajectoryFileError(PlanningError):
    """A trajectory file is missing, not JSON, or not a ``cpr-trajectory/1`` document."""


Number = Annotated[float, Field(allow_inf_nan=False)]


class _Segment(BaseModel):
    model_config = ConfigDict(strict=True)
    t0: Number
    t1: Number
    coeffs: list[list[Number]]


class _Document(BaseModel):
    # other keys are allowed: a tool may add its own beside the documented ones
    model_config = ConfigDict(strict=True, extra="allow")
    format: TrajectoryFormat
    joint_names: Annotated[list[Annotated[str, Field(max_length=100)]], Field(min_length=1, max_length=32)]
    robot: Annotated[str, Field(max_length=4096)]
    scene: dict[str, Any]
    waypoints: list[list[Number]]
    knots: Annotated[list[Number], Field(min_length=2, max_length=MAX_SEGMENTS + 1)]
    segments: Annotated[list[_Segment], Field(min_length=1, max_length=MAX_SEGMENTS)]
    metrics: dict[str, Any] = Field(default_factory=dict)
    task: Annotated[list[dict[str, Any]], Field(max_length=MAX_TASK_ENTRIES)] | None = None


@dataclass(frozen=True)
class TrajectoryFile:
    """A ``cpr-trajectory/1`` file read back.

    Attributes:
        trajectory: the piecewise polynomial.
        joint_names: joint order.
        waypoints: ``(P, nq)`` start, waypoints, goal.
        robot: URDF path recorded in the file.
        scene: the scene section as written.
        metrics: the metrics section as written.
        task: the ``task`` list, what each segment of a task promised (``None``: not a task's);
            :func:`planning.task.check_task` reads its entries.
    """

    trajectory: Trajectory
    joint_names: tuple[str, ...]
    waypoints: FloatArray
    robot: str
    scene: dict[str, Any]
    metrics: dict[str, Any]
    task: list[dict[str, Any]] | None = None
    certified_step_m: float | None = None


def _certified_step(metrics: dict[str, Any], source: str) -> float | None:
    """``metrics``' ``certified_step`` [m] (:func:`~planning.pipeline.settings.recorded_step_m`)."""
    try:
        return recorded_step_m(metrics.get("certified_step"), "metrics.certified_step")
    except PlanningError as exc:
        raise TrajectoryFileError(f"{source}: {exc}") from None


def _consistent(document: _Document) -> str | None:
    """The first inconsistency between knots, segments, coefficients and waypoints, if any."""
    knots, segments, joints = document.knots, document.segments, len(document.joint_names)
    twice = repeated(document.joint_names)
    if twice:
        return f"joint_names = {document.joint_names} names {twice} more than once; each joint once"
    if len(segments) != len(knots) - 1:
        return f"{len(segments)} segments for {len(knots)} knots; expected one segment per knot interval"
    for i, (a, b) in enumerate(itertools.pairwise(knots)):
        if not b - a >= MIN_SEGMENT_S:
            return (
                f"knots[{i + 1}] = {b!r} s must exceed knots[{i}] = {a!r} s by at least {MIN_SEGMENT_S:g} s"
            )
    if knots[-1] - knots[0] > DURATION_RANGE_S[1]:
        return f"lasts {knots[-1] - knots[0]:g} s; at most {DURATION_RANGE_S[1]:g} s"
    for i, segment in enumerate(segments):
        for key, value, knot in (("t0", segment.t0, knots[i]), ("t1", segment.t1, knots[i + 1])):
            if not math.isclose(value, knot, rel_tol=1e-9, abs_tol=1e-12):
                return f"segments[{i}].{key} = {value!r} s, but the knot there is {knot!r} s"
        if len(segment.coeffs) != joints or any(len(c) != ORDER for c in segment.coeffs):
            shape = [len(c) for c in segment.coeffs]
            return f"segments[{i}].coeffs has rows of {shape} values; expected {joints} joints x {ORDER}"
        h = knots[i + 1] - knots[i]
        reach = (np.abs(np.asarray(segment.coeffs)) * h ** np.arange(ORDER)).sum(axis=1).max()
        if not reach <= MAX_POSITION:
            return f"segments[{i}].coeffs reach {reach:.3g}; no joint moves beyond {MAX_POSITION:g} rad or m"
    for k, waypoint in enumerate(document.waypoints):
        if len(waypoint) != joints:
            return f"waypoints[{k}] has {len(waypoint)} values; expected {joints}"
    return None


def parse_trajectory(data: bytes, source: str = "trajectory file") -> TrajectoryFile:
    """Validate the bytes of a ``cpr-trajectory/1`` document and build the :class:`TrajectoryFile`.

    Raises:
        TrajectoryFileError: not JSON, another format, a wrong key or type, or an
            inconsistent trajectory; the message names the key or segment.
    """
    from planning.validation import describe_validation

    try:
        document = _Document.model_validate_json(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        if first["type"] in ("json_invalid", "recursion_loop"):
            raise TrajectoryFileError(f"{source} is not valid JSON: {first['msg']}") from None
        raise TrajectoryFileError(f"{source}: {describe_validation(exc)}") from None
    problem = _consistent(document)
    if problem is not None:
        raise TrajectoryFileError(f"{source}: {problem}")
    coefficients = np.array([segment.coeffs for segment in document.segments], dtype=float)
    return TrajectoryFile(
        trajectory=Trajectory(knots=np.array(document.knots), coefficients=coefficients),
        joint_names=tuple(document.joint_names),
        waypoints=np.array(document.waypoints, dtype=float).reshape(-1, len(document.joint_names)),
        robot=document.robot,
        scene=document.scene,
        metrics=document.metrics,
        task=document.task,
        certified_step_m=_certified_step(document.metrics, source),
    )


def require_continuous(document: TrajectoryFile, source: str = "trajectory file") -> TrajectoryFile:
    """``document`` if its trajectory is continuous (C3) at its knots, by ``check``'s rule.

    For a reader that passes the trajectory on (``export``): ``check`` reports a jump as a
    failure of the trajectory instead (:mod:`planning.curves.continuity`).

    Raises:
        TrajectoryFileError: naming the knot, the joint and the jump.
    """
    jump = discontinuity(document.trajectory, document.joint_names)
    if jump is not None:
        raise TrajectoryFileError(f"{source} {jump}; `cpr-plan check` fails it, so it is not exported")
    return document


def read_trajectory(path: str | Path) -> TrajectoryFile:
    """Read a ``cpr-trajectory/1`` file; raises :class:`TrajectoryFileError` naming what is wrong."""
    path = Path(path)
    try:
        data = read_bytes(path, MAX_TRAJECTORY_BYTES, "trajectory file")
    except UserFileError as exc:
        raise TrajectoryFileError(str(exc)) from None
    return parse_trajectory(data, f"trajectory file '{path}'")
