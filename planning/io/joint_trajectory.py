"""A trajectory as ROS's ``trajectory_msgs/JointTrajectory``, for a controller to execute.

The document has the message's fields: ``header`` (empty frame, zero stamp: "start now"),
``joint_names`` and ``points``, each with ``positions`` [rad, m], ``velocities`` [rad/s, m/s],
``accelerations`` [rad/s^2, m/s^2], empty ``effort`` and ``time_from_start`` as ROS 2's
``builtin_interfaces/Duration`` (``sec``, ``nanosec``). Points are sampled every ``1 / rate_hz``
seconds from the trajectory's start, and at its end. Written as YAML (``.yaml``, ``.yml``) or
JSON (``.json``): what ``ros2 topic pub`` and a ``FollowJointTrajectory`` action client take.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.io.publish import write_file

RATE_RANGE_HZ = (1.0, 10_000.0)
"""Sampling rates :func:`joint_trajectory` accepts [Hz]."""
DEFAULT_RATE_HZ = 100.0
"""Sampling rate unless one is given [Hz]."""
MAX_POINTS = 1_000_000
"""Most points one document holds (a duration times a rate beyond it is refused)."""
SUFFIXES = (".yaml", ".yml", ".json")


def _duration(seconds: float) -> dict[str, int]:
    """``builtin_interfaces/Duration`` of ``seconds`` >= 0, rounded to the nanosecond."""
    total = round(seconds * 1e9)
    return {"sec": total // 1_000_000_000, "nanosec": total % 1_000_000_000}


def joint_trajectory(
    trajectory: Trajectory, joint_names: tuple[str, ...], rate_hz: float = DEFAULT_RATE_HZ
) -> dict[str, Any]:
    """The ``JointTrajectory`` document of ``trajectory`` sampled at ``rate_hz`` [Hz] (module docstring).

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
        times = np.append(times, end)
    else:
        times[-1] = end
    positions, velocities, accelerations = (trajectory(times, r).tolist() for r in range(3))
    points = [
        {
            "positions": positions[k],
            "velocities": velocities[k],
            "accelerations": accelerations[k],
            "effort": [],
            "time_from_start": _duration(float(t - start)),
        }
        for k, t in enumerate(times)
    ]
    header = {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}
    return {"header": header, "joint_names": list(joint_names), "points": points}


def write_joint_trajectory(document: dict[str, Any], path: str | Path) -> Path:
    """Write a :func:`joint_trajectory` document as YAML or JSON by ``path``'s suffix, atomically.

    Raises:
        PlanningError: a suffix other than ``.yaml``, ``.yml`` or ``.json``.
    """
    path = Path(path)
    if path.suffix.lower() not in SUFFIXES:
        raise PlanningError(f"'{path}': the file name must end in one of {list(SUFFIXES)} (YAML or JSON)")
    if path.suffix.lower() == ".json":
        text = json.dumps(document, indent=1)
    else:
        text = yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=1000)
    return write_file(path, text + ("" if text.endswith("\n") else "\n"))
