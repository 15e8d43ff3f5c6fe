"""Files that show a plan: PNG plots and the self-contained meshcat HTML page.

The drawing libraries (matplotlib, meshcat) are imported here only when these are made.
"""

from __future__ import annotations

import html
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.pipeline.result import PlanResult
from planning.viz.carried_objects import CarriedSpan, carried_spans
from planning.viz.measured_clearance import MeasuredClearance, task_clearance

if TYPE_CHECKING:  # the task planner is imported where a task is drawn
    from planning.task.task_plan import TaskMotion

PLOT_FILES = ("joints.png", "tcp_path.png", "clearance.png", "utilisation.png", "convergence.png")


def drawn_files(result: PlanResult, plots: bool = True, page: bool = True) -> dict[str, str | bytes]:
    """The files that draw a plan, those asked for: the plots (:func:`plot_files`), ``viewer.html``."""
    files: dict[str, str | bytes] = dict(plot_files(result)) if plots else {}
    if page:
        files["viewer.html"] = viewer_html(
            result.problem.world, result.scene.safety_margin, result.trajectory, result.waypoints
        )
    return files


TASK_PLOT_FILES = ("joints.png", "tcp_path.png")


def task_drawn_files(task: TaskMotion, plots: bool = True, page: bool = True) -> dict[str, str | bytes]:
    """The files that draw a task: its joints and tool path (:data:`TASK_PLOT_FILES`), ``viewer.html``.

    The junctions are drawn as its waypoints.
    """
    from planning.viz import plots as drawing

    files: dict[str, str | bytes] = {}
    robot, trajectory, scene = task.world.robot, task.trajectory, task.scene
    if plots:
        units = robot.joint_units
        figures = (
            drawing.joint_figure(trajectory, robot.joint_names, units),
            drawing.tcp_path_figure(
                robot,
                trajectory,
                task.junctions,
                task.world.obstacles,
                scene.safety_margin,
                moved_objects(task),
            ),
        )
        files |= {n: drawing.png_bytes(f) for n, f in zip(TASK_PLOT_FILES, figures, strict=True)}
    if page:
        files["viewer.html"] = viewer_html(
            task.world,
            scene.safety_margin,
            trajectory,
            task.junctions,
            carried=task_carried(task),
            measured=task_clearance(task),
        )
    return files


def moved_objects(task: TaskMotion) -> tuple[ck.Obstacle, ...]:
    """What a task takes and leaves, each object where it rests: taken from, and left at."""
    return tuple(
        ck.left_at(task.world.robot, s.payload, task.trajectory(s.t0))
        for s in task.segments
        if s.kind in ("attach", "detach") and s.payload is not None and s.payload.shape is not None
    )


def task_carried(task: TaskMotion) -> tuple[CarriedSpan, ...]:
    """What a task carries, object by object: its scene's payload from the start, then what it attaches."""
    changes = [
        (segment.t0, segment.payload if segment.kind == "attach" else None)
        for segment in task.segments
        if segment.kind in ("attach", "detach")
    ]
    return carried_spans(task.scene.payload, changes, float(task.trajectory.knots[-1]))


def plot_files(result: PlanResult) -> dict[str, bytes]:
    """PNG bytes of the joint, TCP-path, clearance, limit-usage and convergence plots, by file name."""
    from planning.utilisation import limit_usage
    from planning.viz import plots

    robot = result.robot
    units = robot.joint_units
    world = result.problem.world
    figures = (
        plots.joint_figure(result.trajectory, robot.joint_names, units),
        plots.tcp_path_figure(
            robot, result.trajectory, result.waypoints, result.scene.obstacles, result.scene.safety_margin
        ),
        plots.clearance_figure(world, result.trajectory, result.scene.safety_margin),
        plots.utilisation_figure(
            limit_usage(result.trajectory, robot.limits, dynamics=result.problem.dynamics), robot.joint_names
        ),
        plots.convergence_figure(result.optimiser),
    )
    return {name: plots.png_bytes(figure) for name, figure in zip(PLOT_FILES, figures, strict=True)}


def viewer_html(
    world: ck.CollisionWorld,
    margin_m: float,
    trajectory: Trajectory,
    waypoints: NDArray[np.float64],
    collision: bool = False,
    carried: tuple[CarriedSpan, ...] = (),
    *,
    measured: MeasuredClearance | None = None,
) -> str:
    """One self-contained HTML page of the plan, animated.

    It shows the world's robot and obstacles, the margin, waypoints, TCP path and the trajectory,
    and what it ``carried`` (:meth:`~planning.viz.viewer.Viewer.show_carried`); the path is
    coloured by the ``measured`` clearance where given (a task's), else by the world's. A
    loopback meshcat server runs while it is made.
    """
    from planning.viz.viewer import Viewer

    with Viewer(world, margin_m) as viewer:
        viewer.show_geometry(visual=not collision, collision=collision)
        viewer.show_carried(trajectory, carried)
        viewer.show_plan(trajectory, waypoints, measured=measured)
        viewer.animate(trajectory)
        return viewer.static_html()


def notebook_viewer(result: PlanResult | TaskMotion, height_px: int = 480, collision: bool = False) -> Any:
    """The plan's or the task's animated meshcat viewer for a Jupyter cell: an ``IPython.display.HTML``.

    A task shows, as waypoints, the configurations where its segments meet, and what it
    attaches and releases moving with the robot (:func:`task_carried`).

    The self-contained page of :func:`viewer_html` in an iframe (``srcdoc``), so it needs no
    server once drawn and survives in the saved notebook. ``height_px``: the frame's height.
    """
    from IPython.display import HTML

    from planning.task.task_plan import TaskMotion

    if isinstance(result, TaskMotion):
        page = viewer_html(
            result.world,
            result.margin_m,
            result.trajectory,
            result.junctions,
            collision,
            task_carried(result),
            measured=task_clearance(result),
        )
    else:
        page = viewer_html(
            result.problem.world, result.scene.safety_margin, result.trajectory, result.waypoints, collision
        )
    source = html.escape(page, quote=True)
    return HTML(  # type: ignore[no-untyped-call]
        f'<div style="height: {int(height_px)}px; width: 100%; resize: both; overflow: hidden">'
        f'<iframe srcdoc="{source}" style="width: 100%; height: 100%; border: none"></iframe></div>'
    )
