"""A scene file's point-cloud obstacle (docs/formats.md): its schema and its voxels.

``{shape: point_cloud, file: FILE | points: [[x, y, z], ...], resolution, xyz, rpy,
filter_robot, filter_padding}``: the points (or an OctoMap file's occupied voxels) in the
cloud's frame, placed by ``xyz`` and ``rpy``, become the voxels of
:mod:`cpr_kin.shapes.point_clouds`; with ``filter_robot`` the voxels the robot stands in at the
start are left out (:mod:`cpr_kin.collision.self_filter`).
"""

from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Literal, Self

import numpy as np
from pydantic import Field, model_validator

import cpr_kin as ck
from cpr_kin.common.errors import ObstacleError
from cpr_kin.shapes.obstacles import placement
from cpr_kin.shapes.point_clouds import MAX_POINTS, RESOLUTION_RANGE_M
from planning.io.schema_types import FilePath, Name, Point, Strict, Turn, between
from planning.pipeline.scene import MAX_SAFETY_MARGIN_M


class PointCloudSpec(Strict):
    """``{shape: point_cloud, ...}`` (module docstring); FILE relative to the scene.

    ``resolution`` may be left out for an octree file (``.bt``, ``.ot``), whose own it is.
    ``filter_padding`` [m] defaults to the scene's safety margin: what is left then keeps
    the margin from the robot at the start.
    """

    shape: Literal["point_cloud"]
    name: Name | None = None
    file: FilePath | None = None
    points: Annotated[list[Point], Field(min_length=1, max_length=MAX_POINTS)] | None = None
    resolution: Annotated[float, between(*RESOLUTION_RANGE_M)] | None = None
    xyz: Point = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    rpy: Turn = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    filter_robot: bool = False
    filter_padding: Annotated[float, between(0.0, MAX_SAFETY_MARGIN_M)] | None = None

    @model_validator(mode="after")
    def _one_source(self) -> Self:
        if (self.file is None) == (self.points is None):
            raise ValueError(
                "give exactly one of 'file' (a point-cloud or octree file) or 'points' ([[x, y, z], ...] [m])"
            )
        if self.resolution is None and not self.is_octree:
            raise ValueError(
                "'resolution' (the voxels' side [m]) is needed, but for an octree file (.bt, .ot)"
            )
        if self.filter_padding is not None and not self.filter_robot:
            raise ValueError("'filter_padding' goes with 'filter_robot: true'")
        return self

    @property
    def is_octree(self) -> bool:
        """Whether ``file`` is an OctoMap file."""
        from cpr_kin.shapes.octree_files import SUFFIXES  # a cloud's reader, only for a cloud

        return self.file is not None and Path(self.file).suffix.lower() in SUFFIXES


@dataclass(frozen=True)
class RobotAtStart:
    """The robot where a scene starts, for the clouds to be filtered by.

    Attributes:
        robot: the robot with its carried object (:func:`cpr_kin.carrying`).
        q: its start configuration [rad, m].
        padding_m: the default padding: the scene's safety margin [m].
    """

    robot: "ck.Robot"
    q: np.ndarray
    padding_m: float


def cloud_obstacles(
    item: PointCloudSpec, name: str, base: Path, robot_at_start: RobotAtStart | None = None
) -> "list[ck.Obstacle]":
    """A cloud's voxel blocks (:func:`~cpr_kin.shapes.cloud_obstacles.voxel_obstacles`); files from ``base``.

    Args:
        item: the validated entry.
        name: the cloud's name.
        base: the folder its file is relative to.
        robot_at_start: the robot to filter out, needed when ``item.filter_robot``.

    Returns:
        The blocks; none when the filter leaves no voxel.

    Raises:
        cpr_kin.CprKinError: an unreadable file, bad points, a resolution other than the octree's.
    """
    # A scene with a cloud imports what makes its voxels; one without, only the schema's bounds.
    from cpr_kin.collision.self_filter import clear_of_robot
    from cpr_kin.shapes.cloud_obstacles import voxel_obstacles
    from cpr_kin.shapes.octree_files import read_octree
    from cpr_kin.shapes.point_clouds import checked_voxels, read_points, voxel_centres

    if item.file is None:
        points, resolution_m = np.asarray(item.points, dtype=float), float(item.resolution or 0.0)
    elif item.is_octree:
        voxels = read_octree((base / item.file).resolve())
        resolution_m = voxels.resolution_m
        if item.resolution is not None and not np.isclose(item.resolution, resolution_m, rtol=1e-6, atol=0):
            raise ObstacleError(
                f"point cloud '{name}': resolution = {item.resolution:g} m, but the octree "
                f"'{item.file}' has {resolution_m:g} m: leave it out, or give the octree's"
            )
        points = voxels.centres
        if not len(points):
            raise ObstacleError(f"point cloud '{name}': the octree '{item.file}' has no occupied voxel")
    else:
        points, resolution_m = read_points((base / item.file).resolve()), float(item.resolution or 0.0)
    if item.filter_robot:
        if robot_at_start is None:
            raise ObstacleError(f"point cloud '{name}': filter_robot needs the robot and its start")
        points, resolution_m = checked_voxels(points, resolution_m, f"point cloud '{name}'")
        centres = voxel_centres(points, resolution_m)
        padding_m = robot_at_start.padding_m if item.filter_padding is None else item.filter_padding
        cloud_in_world = placement(item.xyz, item.rpy)  # as each block of it is placed
        keep = clear_of_robot(
            robot_at_start.robot, robot_at_start.q, centres, resolution_m, padding_m, cloud_in_world
        )
        if not keep.any():
            return []
        points = centres[keep]
    return voxel_obstacles(points, resolution_m, name, item.xyz, item.rpy)  # the points checked there
