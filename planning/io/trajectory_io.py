"""Files users exchange: the ``cpr-trajectory/1`` JSON (DESIGN.md section 6) and CSV samples.

Every file is written atomically: to a temporary file in the target folder, then renamed,
so a reader never sees half a file and a failure leaves nothing behind.
"""

from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from planning.curves.trajectory import DERIVATIVE_NAMES, Trajectory

if TYPE_CHECKING:  # types only: writing files needs neither the planner nor the robot
    import cpr_kin as ck
    from planning.planner import PlanResult
    from planning.scene import Scene, Target

FloatArray = NDArray[np.float64]
FORMAT = "cpr-trajectory/1"


def write_files(folder: Path, files: dict[str, str | bytes]) -> list[Path]:
    """Write every file into ``folder``, or none: all go to temporary names first, then are renamed."""
    folder.mkdir(parents=True, exist_ok=True)
    temporary: list[tuple[str, Path]] = []
    try:
        for name, content in files.items():
            handle, temporary_name = tempfile.mkstemp(prefix=f".{name}.", dir=folder)
            with os.fdopen(handle, "wb") as stream:
                stream.write(content.encode("utf-8") if isinstance(content, str) else content)
            temporary.append((name, Path(temporary_name)))
        for name, written in temporary:
            os.replace(written, folder / name)
    finally:
        for _, leftover in temporary:
            leftover.unlink(missing_ok=True)
    return [folder / name for name in files]


def atomic_write_text(path: Path, text: str) -> None:
    """Write ``text`` to ``path`` through a temporary file and a rename."""
    path = Path(path)
    write_files(path.parent, {path.name: text})


def obstacle_to_dict(obstacle: ck.Obstacle) -> dict[str, Any]:
    """An obstacle in the scene file's form (DESIGN.md section 6)."""
    entry: dict[str, Any] = {"name": obstacle.name, "shape": obstacle.shape}
    if obstacle.shape == "box":
        entry["size"] = np.asarray(obstacle.size).tolist()
    if obstacle.shape in ("sphere", "cylinder", "capsule"):
        entry["radius"] = obstacle.radius
    if obstacle.shape in ("cylinder", "capsule"):
        entry["length"] = obstacle.length
    if obstacle.shape == "mesh":
        entry.update(mesh=str(obstacle.mesh), scale=obstacle.scale, convex=obstacle.convex)
    entry.update(xyz=obstacle.xyz.tolist(), rpy=obstacle.rpy.tolist())
    return entry


def target_to_dict(target: Target) -> dict[str, Any]:
    """A start or goal in the scene file's form."""
    if target.q is not None:
        return {"q": [float(v) for v in target.q]}
    entry: dict[str, Any] = {"tcp": [float(v) for v in target.tcp or ()]}
    if target.theta4 or target.theta5:
        entry.update(theta4=target.theta4, theta5=target.theta5)
    return entry


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The scene as planned: obstacles, safety margin, start, goal (and duration)."""
    return {
        "name": scene.name,
        "safety_margin": scene.safety_margin,
        "start": target_to_dict(scene.start),
        "goal": target_to_dict(scene.goal),
        "duration": scene.duration,
        "obstacles": [obstacle_to_dict(o) for o in scene.obstacles],
    }


def trajectory_document(result: PlanResult, timings: bool = False) -> dict[str, Any]:
    """The ``cpr-trajectory/1`` document of a plan, as plain JSON types.

    Wall times (``planning_time_s``, ``optimiser_time_s``) are ``null`` unless ``timings``:
    the same scene and seed then give the same file, byte for byte.
    """
    from planning.io.report import plan_record

    trajectory = result.trajectory
    segments = [
        {"t0": float(t0), "t1": float(t1), "coeffs": trajectory.coefficients[i].tolist()}
        for i, (t0, t1) in enumerate(zip(trajectory.knots[:-1], trajectory.knots[1:], strict=True))
    ]
    return {
        "format": FORMAT,
        "joint_names": list(result.joint_names),
        "robot": str(result.robot.urdf_path),
        "scene": scene_to_dict(result.scene),
        "waypoints": result.waypoints.tolist(),
        "knots": trajectory.knots.tolist(),
        "segments": segments,
        "metrics": plan_record(result, timings),
    }


def write_trajectory(result: PlanResult, path: Path, timings: bool = False) -> None:
    """Write the plan as a ``cpr-trajectory/1`` JSON file, atomically (see :func:`trajectory_document`)."""
    atomic_write_text(Path(path), json.dumps(trajectory_document(result, timings), indent=1) + "\n")


def samples_csv(trajectory: Trajectory, joint_names: tuple[str, ...], period: float) -> str:
    """CSV text of position, velocity, acceleration and jerk every ``period`` seconds."""
    times = np.append(np.arange(trajectory.knots[0], trajectory.knots[-1], period), trajectory.knots[-1])
    columns = [trajectory(times, r) for r in range(4)]
    header = ["t"]
    for r in range(4):
        suffix = "" if r == 0 else f"_{DERIVATIVE_NAMES[r]}"
        header += [f"{name}{suffix}" for name in joint_names]
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(header)
    # numbers need no quoting: one %-format per row is several times faster than csv's writer
    row = ",".join(["%.6f", *["%.12g"] * (4 * len(joint_names))]) + "\n"
    values = np.column_stack([times, *columns]).tolist()
    buffer.write("".join([row % tuple(v) for v in values]))
    return buffer.getvalue()


def write_samples(result: PlanResult, path: Path) -> None:
    """Write the trajectory sampled at the planner's IPO period as CSV, atomically."""
    atomic_write_text(
        Path(path), samples_csv(result.trajectory, result.joint_names, result.scene.planner.ipo)
    )
