from __future__ import annotations

import struct

import matplotlib.pyplot as plt
import numpy as np
import pytest

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult
from planning.viz import plots
from planning.viz.artifacts import PLOT_FILES, plot_files


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
