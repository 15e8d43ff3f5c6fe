"""Plots of a planned trajectory as PNG files (matplotlib, Agg backend).

Imported only when plots are asked for: ``import planning`` never loads matplotlib.

- :func:`joint_figure`: position, velocity, acceleration and jerk of the moving joints
  against time, waypoints marked (the paper's fig. 4). The curves are sampled on a fine grid
  plus the knots and the exact extremum instants, so their extrema are the metrics'.
- :func:`tcp_path_figure`: the 3-D TCP path with the obstacles and margin (fig. 3).
- :func:`clearance_figure`: clearance against time with the margin line.
- :func:`utilisation_figure`: how much of each limit (kinematic, and torque) the motion uses over time.
- :func:`convergence_figure`: the firefly's best and mean fitness per iteration.
"""

from __future__ import annotations

import io
import itertools
from typing import Any

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import DERIVATIVE_NAMES, Trajectory
from planning.search.optimizer import SearchResult
from planning.utilisation import LimitUsage

FloatArray = NDArray[np.float64]
UNITS = {"rad": ("rad", "rad/s", "rad/s$^2$", "rad/s$^3$"), "m": ("m", "m/s", "m/s$^2$", "m/s$^3$")}


def sample_times(trajectory: Trajectory, count: int = 1000) -> FloatArray:
    """A fine time grid with the knots and every exact extremum instant of orders 0 to 3."""
    extra = [trajectory.knots]
    for r in range(4):
        extrema = trajectory.extrema(r)
        extra += [extrema.time_of_minimum, extrema.time_of_maximum]
    return np.unique(np.concatenate([np.linspace(trajectory.knots[0], trajectory.knots[-1], count), *extra]))


def _moving(trajectory: Trajectory, tolerance: float = 1e-12) -> list[int]:
    extrema = trajectory.extrema(0)
    return [j for j in range(trajectory.n_joints) if extrema.maximum[j] - extrema.minimum[j] > tolerance]


def joint_figure(trajectory: Trajectory, joint_names: tuple[str, ...], units: tuple[str, ...]) -> Figure:
    """Position, velocity, acceleration and jerk of the moving joints, knots marked."""
    times = sample_times(trajectory)
    moving = _moving(trajectory) or list(range(trajectory.n_joints))
    figure, axes = plt.subplots(4, len(moving), figsize=(3.2 * len(moving), 9), sharex=True, squeeze=False)
    for column, j in enumerate(moving):
        for r in range(4):
            ax = axes[r, column]
            ax.plot(
                times, trajectory(times, r)[:, j], color="C0", label=f"{joint_names[j]} {DERIVATIVE_NAMES[r]}"
            )
            ax.plot(
                trajectory.knots,
                trajectory(trajectory.knots, r)[:, j],
                "o",
                color="C1",
                markersize=4,
                label="nodes",
            )
            ax.set_ylabel(f"{DERIVATIVE_NAMES[r]} [{UNITS[units[j]][r]}]")
            ax.grid(alpha=0.3)
        axes[0, column].set_title(joint_names[j])
        axes[-1, column].set_xlabel("t [s]")
    figure.suptitle("Joint trajectories: position, velocity, acceleration, jerk (nodes marked)")
    figure.tight_layout()
    return figure


def _box_corners(obstacle: ck.Obstacle, grows: tuple[float, ...]) -> list[FloatArray]:
    """``(8, 3)`` the corners of the obstacle's bounding box grown by each of ``grows`` [m], in the world.

    The box about coal's geometry in the obstacle's frame (a mesh's, a round shape's: built
    once, a mesh read once), or about the occupied voxels' centres.
    """
    if obstacle.shape == "voxels":  # coal's octree is bounded by its root cube, not by what it holds
        points, half_side = np.asarray(obstacle.points), float(obstacle.resolution or 0.0) / 2
        low, high = points.min(axis=0) - half_side, points.max(axis=0) + half_side
    else:
        geometry = obstacle.geometry()
        geometry.computeLocalAABB()
        low, high = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    placement = obstacle.placement
    rotation, translation = np.asarray(placement.rotation), np.asarray(placement.translation)
    return [
        np.array(list(itertools.product(*zip(low - grow, high + grow, strict=True)))) @ rotation.T
        + translation
        for grow in grows
    ]


def _box_faces(corners: FloatArray) -> list[FloatArray]:
    """The six faces of a box from its ``(8, 3)`` corners (:func:`_box_corners`' order)."""
    faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
    return [corners[f] for f in faces]


def tcp_path_figure(
    robot: ck.Robot,
    trajectory: Trajectory,
    waypoints: FloatArray,
    obstacles: tuple[ck.Obstacle, ...],
    margin_m: float,
    moved: tuple[ck.Obstacle, ...] = (),
) -> Figure:
    """The TCP path in 3-D with the obstacles and the margin as translucent shells.

    Obstacles are drawn as their bounding boxes; ``moved`` (what a task takes or leaves) in
    another colour, where each rests. The axes span what is drawn, at one scale [m].
    """
    times = np.linspace(trajectory.knots[0], trajectory.knots[-1], 400)
    tcp = ck.frame_positions(robot, trajectory(times))
    nodes = ck.frame_positions(robot, waypoints)
    figure = plt.figure(figsize=(7, 6))
    ax: Any = figure.add_subplot(projection="3d")
    ax.plot(*tcp.T, color="C0", label="TCP path")
    ax.scatter(*nodes.T, color="C1", s=25, label="waypoints", depthshade=False)
    drawn = [tcp, nodes]
    for group, colour, label in ((obstacles, "#d9534f", "obstacles"), (moved, "#5b8fd9", "objects moved")):
        for k, obstacle in enumerate(group):
            solid, shell = _box_corners(obstacle, (0.0, margin_m))
            faces = Poly3DCollection(_box_faces(solid), facecolor=colour, alpha=0.7, edgecolor="k")
            faces.set_label(label if k == 0 else None)
            ax.add_collection3d(faces)
            if margin_m > 0:
                ax.add_collection3d(Poly3DCollection(_box_faces(shell), facecolor=colour, alpha=0.12))
            drawn.append(shell)
    low, high = np.min([d.min(axis=0) for d in drawn], axis=0), np.max([d.max(axis=0) for d in drawn], axis=0)
    pad = 0.05 * float(np.max(high - low)) + 1e-3
    ax.set_xlim(low[0] - pad, high[0] + pad)
    ax.set_ylim(low[1] - pad, high[1] + pad)
    ax.set_zlim(low[2] - pad, high[2] + pad)
    ax.set_box_aspect(high - low + 2 * pad)  # one metre as long on every axis
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.legend(loc="upper left")
    ax.set_title("TCP path, obstacles and safety margin")
    return figure


def clearance_figure(world: ck.CollisionWorld, trajectory: Trajectory, margin_m: float) -> Figure:
    """Clearance of each collision group against time, with the margin line."""
    times = np.linspace(trajectory.knots[0], trajectory.knots[-1], 600)
    clearance = world.clearance_batch(trajectory(times)).clearance_m
    figure, ax = plt.subplots(figsize=(8, 4))
    for g, group in enumerate(ck.GROUPS):
        ax.plot(times, clearance[:, g], label=f"{group} clearance")
    ax.axhline(margin_m, color="k", linestyle="--", label=f"safety margin {margin_m} m")
    ax.set_ylim(bottom=min(0.0, float(np.nanmin(clearance))))
    ax.set_xlabel("t [s]")
    ax.set_ylabel("clearance [m]")
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title("Clearance to the obstacles")
    figure.tight_layout()
    return figure


def utilisation_figure(usage: LimitUsage, joint_names: tuple[str, ...]) -> Figure:
    """Largest |velocity|, |acceleration|, |jerk| (|torque|) over its limit among the joints, against time.

    Where the curves stay near 1 the motion runs at its limits; where all stay low, time is
    left on the table. The shading marks which joint holds the largest usage of each order.
    """
    rows = len(usage.orders)
    figure, axes = plt.subplots(rows, 1, figsize=(8, 2 * rows), sharex=True)
    for r, (ax, order) in enumerate(zip(axes, usage.orders, strict=True)):
        ax.plot(usage.times, usage.usage[:, r], color=f"C{r}")
        ax.axhline(1.0, color="k", linestyle="--", linewidth=0.8)
        for j, name in enumerate(joint_names):
            held = usage.binding[:, r] == j
            if held.any() and np.ptp(usage.times[held]) > 0:
                ax.fill_between(usage.times, 0, 1.05, where=held, alpha=0.08, color=f"C{j + 3}", label=name)
        ax.set_ylim(0.0, 1.05)
        ax.set_ylabel(f"{order} / limit")
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right", fontsize="small", ncol=len(joint_names), title="largest: joint")
    axes[0].set_title(f"Limit usage over time (mean {', '.join(f'{m:.2f}' for m in usage.mean())})")
    axes[-1].set_xlabel("t [s]")
    figure.tight_layout()
    return figure


def convergence_figure(result: SearchResult) -> Figure:
    """Best and mean fitness per firefly iteration, then per refinement generation (if any)."""
    figure, ax = plt.subplots(figsize=(7, 4))
    iterations = np.arange(len(result.best_history))
    ax.plot(iterations, result.best_history, label="best")
    ax.plot(iterations, result.mean_history, label="population mean", alpha=0.7)
    ax.set_yscale("log")
    ax.set_xlabel("firefly iteration, then CMA-ES generation")
    ax.set_ylabel("fitness")
    ax.grid(alpha=0.3, which="both")
    ax.legend()
    ax.set_title(f"Search convergence ({result.evaluations} evaluations)")
    figure.tight_layout()
    return figure


def png_bytes(figure: Figure) -> bytes:
    """The figure as PNG bytes; the figure is closed."""
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=100)
    plt.close(figure)
    return buffer.getvalue()
