"""The robot's own voxels in a point cloud: those its collision shapes come near at a configuration.

A camera that sees the workspace sees the robot in it. Every peer filters those points out
before they become obstacles (MoveIt's self filter, roboplan's, mplib's); here a cloud's voxels
(cubes of side ``resolution`` [m], :mod:`cpr_kin.shapes.point_clouds`) are kept only when each lies
farther than ``padding`` [m] from every collision geometry of the robot (its carried object
included) at the given configuration, measured by coal between the voxel's cube and the
geometry. A voxel's centre more than ``padding`` plus its half diagonal outside a geometry's
bounding box is clear of it without a query. Where a link's exact mesh decides
(:mod:`cpr_kin.shapes.exact_meshes`), a voxel near its hull is the robot's only if it is near the mesh
or its centre inside it: a voxel in a concave link's hollow stays an obstacle.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import CprKinError
from cpr_kin.model.robot import Robot
from cpr_kin.shapes.coal_queries import as_transform

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


def clear_of_robot(
    robot: Robot,
    q: ArrayLike,
    centres: ArrayLike,
    resolution_m: float,
    padding_m: float,
    cloud_in_world: pin.SE3 | None = None,
) -> BoolArray:
    """Which voxels are farther than ``padding_m`` from every collision geometry of ``robot`` at ``q``.

    Args:
        robot: the robot (with its carried object, :func:`cpr_kin.carrying`).
        q: its configuration [rad, m].
        centres: ``(N, 3)`` the voxels' centres in the cloud's frame [m].
        resolution_m: the voxels' side [m], along the cloud frame's axes.
        padding_m: the distance within which a voxel is the robot's own [m], >= 0.
        cloud_in_world: the cloud frame's placement (default: the world's).

    Returns:
        ``(N,)`` true for the voxels to keep.

    Raises:
        CprKinError: a negative or non-finite padding.
    """
    import coal

    if not (math.isfinite(padding_m) and padding_m >= 0.0):
        raise CprKinError(f"the filter's padding = {padding_m} m must be a finite distance >= 0")
    placement = cloud_in_world if cloud_in_world is not None else pin.SE3.Identity()
    in_world = np.asarray(centres, dtype=float) @ placement.rotation.T + placement.translation
    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    pin.updateGeometryPlacements(
        robot.model, data, robot.collision_model, geometry_data, np.asarray(q, dtype=float)
    )
    voxel = coal.Box(resolution_m, resolution_m, resolution_m)
    reach = padding_m + resolution_m * math.sqrt(3.0) / 2.0
    keep = np.ones(len(in_world), dtype=bool)
    request = coal.DistanceRequest()
    for geometry in robot.geometries:
        shape = robot.collision_model.geometryObjects[geometry.index].geometry
        shape_in_world = geometry_data.oMg[geometry.index]
        shape.computeLocalAABB()
        box = shape.aabb_local
        local = (in_world - shape_in_world.translation) @ shape_in_world.rotation
        near = keep & np.all((local >= box.min_ - reach) & (local <= box.max_ + reach), axis=1)
        shape_pose = as_transform(shape_in_world)
        mesh = robot.exact_meshes.get(geometry.index)
        mesh_in_world = shape_in_world * mesh.mesh_in_shape if mesh is not None else None
        for k in np.flatnonzero(near):
            voxel_pose = coal.Transform3s(placement.rotation, in_world[k])
            if (
                coal.distance(shape, shape_pose, voxel, voxel_pose, request, coal.DistanceResult())
                > padding_m
            ):
                continue
            if mesh is not None and mesh_in_world is not None:
                on_mesh = coal.distance(
                    mesh.bvh, as_transform(mesh_in_world), voxel, voxel_pose, request, coal.DistanceResult()
                )
                if on_mesh > padding_m and not mesh.holds(mesh_in_world.actInv(in_world[k])[None])[0]:
                    continue
            keep[k] = False
    return keep
