from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult
from planning.viz import plots
from planning.viz.artifacts import PLOT_FILES, moved_objects, plot_files, task_drawn_files
from tests.conftest import PlannedTask, spline_path


@pytest.fixture(scope="module")
def result(robot: ck.Robot) -> PlanResult:
    return plan(paper_scene(0), robot)


def png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    width, height = struct.unpack(">II", data[16:24])
    return width, height


def test_plot_files_are_valid_pngs(result: PlanResult) -> None:
    files = plot_files(result)
    assert sorted(files) == sorted(PLOT_FILES)
    for data in files.values():
        width, height = png_size(data)
        assert width > 300 and height > 300


def test_joint_curves_carry_the_metrics(result: PlanResult, robot: ck.Robot) -> None:
    units = tuple(robot.joint_unit(n) for n in robot.joint_names)
    figure = plots.joint_figure(result.trajectory, robot.joint_names, units)
    axes = np.array(figure.axes).reshape(4, -1)
    assert axes.shape[1] == 3  # the wrist does not move in the paper case
    for column, name in enumerate(("theta1", "d2", "d3")):
        jerk = axes[3, column].lines[0].get_ydata()
        assert np.min(jerk) == pytest.approx(result.metrics.jerk_min[name], abs=1e-12)
        assert np.max(jerk) == pytest.approx(result.metrics.jerk_max[name], abs=1e-12)
        nodes = axes[0, column].lines[1]
        np.testing.assert_allclose(nodes.get_xdata(), result.trajectory.knots)
        j = robot.joint_names.index(name)
        values = np.asarray(nodes.get_ydata())
        np.testing.assert_allclose(values[[0, -1]], result.waypoints[[0, -1], j], atol=1e-12)
    plt.close(figure)


def test_clearance_and_convergence_curves(result: PlanResult, robot: ck.Robot) -> None:
    world = ck.CollisionWorld(robot, result.scene.obstacles)
    figure = plots.clearance_figure(world, result.trajectory, 0.1)
    lines = figure.axes[0].lines
    lowest = min(float(np.min(line.get_ydata())) for line in lines[:2])
    assert lowest >= result.metrics.min_clearance_m - 1e-9  # the certified bound is below any sample
    assert np.asarray(lines[2].get_ydata())[0] == 0.1  # the margin line
    plt.close(figure)
    figure = plots.convergence_figure(result.optimiser)
    np.testing.assert_array_equal(figure.axes[0].lines[0].get_ydata(), result.optimiser.best_history)
    plt.close(figure)


def test_tcp_path_figure(result: PlanResult, robot: ck.Robot) -> None:
    figure = plots.tcp_path_figure(robot, result.trajectory, result.waypoints, result.scene.obstacles, 0.1)
    path = figure.axes[0].lines[0].get_data_3d()  # type: ignore[attr-defined]
    np.testing.assert_allclose(np.array(path)[:, 0], (0.5, 0.45, 0.25), atol=1e-9)
    np.testing.assert_allclose(np.array(path)[:, -1], (-0.5, 0.45, 0.25), atol=1e-9)
    plt.close(figure)


def test_the_tcp_path_figure_spans_what_it_draws_at_one_scale(tmp_path: Path) -> None:
    """A Panda's path, a shelf above it and a part behind it: all in view, a metre as long
    on every axis, and a mesh drawn as trimesh's bounding box of it (not a stand-in cube)."""
    panda = ck.load_robot(example_robot("panda"))
    q0, q1 = np.zeros(panda.nq), np.full(panda.nq, 0.3)
    q0[3], q1[3] = -0.1, -1.5  # the elbow within its range
    trajectory = spline_path(np.stack([q0, 0.5 * (q0 + q1), q1]))
    part = trimesh.creation.icosphere(radius=0.07)
    part.apply_translation([0.02, -0.01, 0.03])  # off its frame's origin
    part.export(tmp_path / "part.stl")
    mesh = ck.Obstacle.from_mesh(
        tmp_path / "part.stl", xyz=[-1.1, 0.4, 0.2], rpy=[0.3, 0.0, 0.7], name="part"
    )
    shelf = ck.Obstacle.box([0.3, 1.2, 0.05], [1.3, 0.0, 1.5], name="shelf")
    placed = trimesh.transformations.euler_matrix(0.3, 0.0, 0.7, "sxyz")  # type: ignore[no-untyped-call]
    placed[:3, 3] = [-1.1, 0.4, 0.2]
    corners = trimesh.bounds.corners(part.bounds)  # type: ignore[no-untyped-call]
    oracle = corners @ placed[:3, :3].T + placed[:3, 3]
    drawn = plots._box_corners(mesh, (0.0,))[0]
    order = [np.lexsort(np.round(corners, 4).T) for corners in (drawn, oracle)]
    np.testing.assert_allclose(drawn[order[0]], oracle[order[1]], atol=1e-6)  # the STL's float32
    figure = plots.tcp_path_figure(panda, trajectory, trajectory(trajectory.knots), (shelf, mesh), 0.05)
    ax: Any = figure.axes[0]
    limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    tcp = np.array(ax.lines[0].get_data_3d()).T
    assert limits[2, 1] > 1.5 and limits[0, 0] < -1.1  # beyond the CPR's old view, [-0.9, 0.9]^2 x [0, 1] m
    shelf_shell = np.array([[1.15 - 0.05, -0.65, 1.475 - 0.05], [1.45 + 0.05, 0.65, 1.525 + 0.05]])
    for points in (tcp, oracle, shelf_shell):
        assert np.all(points >= limits[:, 0]) and np.all(points <= limits[:, 1])
    ranges = limits[:, 1] - limits[:, 0]
    aspect = np.asarray(ax.get_box_aspect())
    np.testing.assert_allclose(aspect / aspect[0], ranges / ranges[0], rtol=1e-9)
    plt.close(figure)


def test_a_task_s_tool_path_shows_what_it_moves_where_it_rests(pick_and_place: PlannedTask) -> None:
    """The part drawn where the attach takes it (where the scene puts it) and where the detach
    leaves it, and no longer among the obstacles that stay."""
    task, scene = pick_and_place.task, pick_and_place.read.scene
    taken, left = moved_objects(task)
    part = next(o for o in scene.obstacles if o.name == "part")
    np.testing.assert_allclose(taken.placement.homogeneous, part.placement.homogeneous, atol=1e-9)
    attach, detach = (next(s for s in task.segments if s.kind == kind) for kind in ("attach", "detach"))
    tcp = ck.frame_poses(task.world.robot, task.trajectory(np.array([attach.t0, detach.t0])))
    in_hand = [np.linalg.solve(tcp[k], shape.placement.homogeneous) for k, shape in enumerate((taken, left))]
    np.testing.assert_allclose(in_hand[0], in_hand[1], atol=1e-9)  # carried rigidly between
    assert "part" not in {o.name for o in task.world.obstacles}
    drawn = task_drawn_files(task, plots=True, page=False)["tcp_path.png"]
    assert isinstance(drawn, bytes) and png_size(drawn)[0] > 0
