"""A trajectory as ROS's ``trajectory_msgs/JointTrajectory``, for a controller to execute.

The document has the message's fields: ``header`` (empty frame, zero stamp: "start now"),
``joint_names`` and ``points``, each with ``positions`` [rad, m], ``velocities`` [rad/s, m/s],
``accelerations`` [rad/s^2, m/s^2], empty ``effort`` and ``time_from_start`` as ROS 2's
``builtin_interfaces/Duration`` (``sec``, ``nanosec``). Points are sampled every ``1 / rate_hz``
seconds from the trajectory's start, and at its end. Written as YAML (``.yaml``, ``.yml``) or
JSON (``.json``): what ``ros2 topic pub`` and a ``FollowJointTrajectory`` action client take.

:func:`write_joint_trajectory` streams the points, :data:`CHUNK_POINTS` at a time: its memory
does not grow with the number of points (up to :data:`MAX_POINTS`).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from cpr_kin.common.user_files import YAML_SUFFIXES
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.io.publish import write_file

RATE_RANGE_HZ = (1.0, 10_000.0)
"""Sampling rates :func:`joint_trajectory` accepts [Hz]."""
DEFAULT_RATE_HZ = 100.0
"""Sampling rate unless one is given [Hz]."""
MAX_POINTS = 1_000_000
"""Most points one document holds (a duration times a rate beyond it is refused)."""
CHUNK_POINTS = 10_000
"""Points evaluated and written at a time."""
SUFFIXES = (*YAML_SUFFIXES, ".json")
POINT_KEYS = ("positions", "velocities", "accelerations")


def _duration(seconds: float) -> dict[str, int]:
    """``builtin_interfaces/Duration`` of ``seconds`` >= 0, rounded to the nanosecond."""
    total = round(seconds * 1e9)
    return {"sec": total // 1_000_000_000, "nanosec": total % 1_000_000_000}


def sample_times(trajectory: Trajectory, rate_hz: float = DEFAULT_RATE_HZ) -> np.ndarray:
    """The times the points are sampled at [s]: every ``1 / rate_hz`` from the start, and the end.

    Raises:
        PlanningError: a rate outside :data:`RATE_RANGE_HZ`, or more than :data:`MAX_POINTS` points.
    """
    low, high = RATE_RANGE_HZ
    if not (isinstance(rate_hz, int | float) and math.isfinite(rate_hz) and low <= rate_hz <= high):
        raise PlanningError(f"rate = {rate_hz!r} Hz must be a number in [{low:g}, {high:g}] Hz")
    start, end = float(trajectory.knots[0]), float(trajectory.knots[-1])
    count = math.floor((end - start) * rate_hz + 1e-9) + 1
    if count + 1 > MAX_POINTS:
        raise PlanningError(
            f"{end - start:g} s at {rate_hz:g} Hz is {count} points; at most {MAX_POINTS}: lower --rate"
        )
    times = start + np.arange(count) / rate_hz
    if end - times[-1] > 1e-9:
        return np.append(times, end)
    times[-1] = end
    return times


def _points(trajectory: Trajectory, times: np.ndarray) -> Iterator[dict[str, Any]]:
    """The points at ``times``, evaluated :data:`CHUNK_POINTS` at a time."""
    start = float(trajectory.knots[0])
    for first in range(0, len(times), CHUNK_POINTS):
        chunk = times[first : first + CHUNK_POINTS]
        positions, velocities, accelerations = (trajectory(chunk, r).tolist() for r in range(3))
        for k, t in enumerate(chunk.tolist()):
            yield {
                "positions": positions[k],
                "velocities": velocities[k],
                "accelerations": accelerations[k],
                "effort": [],
                "time_from_start": _duration(t - start),
            }


def _header(joint_names: tuple[str, ...]) -> dict[str, Any]:
    return {"header": {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}, "joint_names": list(joint_names)}


def joint_trajectory(
    trajectory: Trajectory, joint_names: tuple[str, ...], rate_hz: float = DEFAULT_RATE_HZ
) -> dict[str, Any]:
    """The ``JointTrajectory`` document of ``trajectory`` sampled at ``rate_hz`` [Hz] (module docstring).

    The whole document in memory; :func:`write_joint_trajectory` streams it to a file.

    Raises:
        PlanningError: a rate outside :data:`RATE_RANGE_HZ`, or more than :data:`MAX_POINTS` points.
    """
    points = list(_points(trajectory, sample_times(trajectory, rate_hz)))
    return {**_header(joint_names), "points": points}


def _yaml_float(value: float) -> str:
    """``value`` as YAML 1.1 (PyYAML) reads back as the same float: an exponent needs a dot."""
    text = repr(value)
    return text.replace("e", ".0e", 1) if "e" in text and "." not in text else text


def _in_chunks(texts: Iterator[str]) -> Iterator[str]:
    """``texts`` joined :data:`CHUNK_POINTS` at a time: few writes, and never the whole file in memory."""
    chunk: list[str] = []
    for text in texts:
        chunk.append(text)
        if len(chunk) == CHUNK_POINTS:
            yield "".join(chunk)
            chunk = []
    yield "".join(chunk)


def _yaml_point(point: dict[str, Any]) -> str:
    """One point as a YAML list item, block style with flow-style lists (as ``yaml.safe_dump`` writes it)."""
    rows = [f"[{', '.join(map(_yaml_float, point[key]))}]" for key in POINT_KEYS]
    stamp = point["time_from_start"]
    return (
        f"- positions: {rows[0]}\n  velocities: {rows[1]}\n  accelerations: {rows[2]}\n  effort: []\n"
        f"  time_from_start: {{sec: {stamp['sec']}, nanosec: {stamp['nanosec']}}}\n"
    )


def _yaml_parts(header: dict[str, Any], points: Iterator[dict[str, Any]]) -> Iterator[str]:
    """The document as YAML, as ``yaml.safe_dump`` would write it."""
    yield yaml.safe_dump(header, sort_keys=False, default_flow_style=None, width=1000)
    yield "points:\n"
    yield from _in_chunks(map(_yaml_point, points))


def _json_parts(header: dict[str, Any], points: Iterator[dict[str, Any]]) -> Iterator[str]:
    """The document as JSON, one point a line."""
    yield json.dumps(header)[:-1] + ', "points": [\n'
    yield from _in_chunks(("" if k == 0 else ",\n") + json.dumps(point) for k, point in enumerate(points))
    yield "\n]}\n"


def write_joint_trajectory(
    trajectory: Trajectory,
    joint_names: tuple[str, ...],
    path: str | Path,
    rate_hz: float = DEFAULT_RATE_HZ,
) -> Path:
    """Write the ``JointTrajectory`` of ``trajectory`` as YAML or JSON by ``path``'s suffix, atomically.

    The points are streamed (module docstring): memory stays small up to :data:`MAX_POINTS`.

    Raises:
        PlanningError: a suffix other than ``.yaml``, ``.yml`` or ``.json``; a rate outside
            :data:`RATE_RANGE_HZ`, or more than :data:`MAX_POINTS` points.
    """
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise PlanningError(f"'{path}': the file name must end in one of {list(SUFFIXES)} (YAML or JSON)")
    points = _points(trajectory, sample_times(trajectory, rate_hz))
    parts = _json_parts if path.suffix.lower() == ".json" else _yaml_parts
    return write_file(path, parts(_header(joint_names), points))
