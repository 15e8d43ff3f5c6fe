"""A tool line's geometry against independent oracles: scipy's slerp, and the offset's frames."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from scipy.spatial.transform import Rotation, Slerp

from planning.task.tool_line import LineGeometry, ToolLine, ToolPose


def geometry(seed: int) -> LineGeometry:
    rng = np.random.default_rng(seed)
    start = pin.SE3(Rotation.random(random_state=rng).as_matrix(), rng.normal(size=3))
    goal = pin.SE3(Rotation.random(random_state=rng).as_matrix(), rng.normal(size=3))
    return LineGeometry(start, goal)


def test_the_orientations_along_the_line_are_scipys_slerp() -> None:
    for seed in range(5):
        line = geometry(seed)
        sigma = np.linspace(0.0, 1.0, 11)
        ends = Rotation.from_matrix([line.start.rotation, line.goal.rotation])
        expected = Slerp([0.0, 1.0], ends)(sigma).as_matrix()
        np.testing.assert_allclose(line.rotations(sigma), expected, atol=1e-12)
        np.testing.assert_allclose([line.pose(s).rotation for s in sigma], expected, atol=1e-12)
        np.testing.assert_allclose(
            line.pose(0.5).translation, 0.5 * (line.start.translation + line.goal.translation)
        )


def test_the_progress_of_a_point_on_the_line_is_its_own() -> None:
    line = geometry(7)
    sigma = np.array([0.0, 0.25, 0.6, 1.0])
    points = line.start.translation + sigma[:, None] * line.shift_m
    np.testing.assert_allclose(line.progress(points, line.rotations(sigma)), sigma, atol=1e-12)
    beyond = line.start.translation + np.array([-0.5, 1.5])[:, None] * line.shift_m
    np.testing.assert_allclose(line.progress(beyond, line.rotations([0.0, 1.0])), [0.0, 1.0])
    turning = LineGeometry(line.start, pin.SE3(line.goal.rotation, line.start.translation))
    still = np.repeat(line.start.translation[None], 4, axis=0)
    np.testing.assert_allclose(turning.progress(still, turning.rotations(sigma)), sigma, atol=1e-9)


def test_an_offset_in_the_tool_frame_moves_along_the_tools_axes_and_keeps_its_orientation() -> None:
    start = geometry(3).start
    in_tool = ToolLine(by=(0.0, 0.0, 0.1), offset_frame="tool").goal(start)
    np.testing.assert_allclose(
        in_tool.translation - start.translation, 0.1 * start.rotation[:, 2], atol=1e-15
    )
    np.testing.assert_array_equal(in_tool.rotation, start.rotation)
    in_base = ToolLine(by=(0.0, 0.0, 0.1), offset_frame="base").goal(start)
    np.testing.assert_allclose(in_base.translation - start.translation, [0.0, 0.0, 0.1], atol=1e-15)
    pose = ToolPose.of(in_base)
    np.testing.assert_allclose(pose.placement().homogeneous, in_base.homogeneous, atol=1e-12)
