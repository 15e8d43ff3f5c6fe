"""A point cloud as obstacles (voxels in blocks, :mod:`cpr_kin.shapes.point_clouds`); points on obstacles."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import ObstacleError
from cpr_kin.shapes.obstacles import Obstacle
from cpr_kin.shapes.point_clouds import checked_voxels, voxel_blocks, voxel_centres

FloatArray = NDArray[np.float64]


def voxel_obstacles(
    points: ArrayLike,
    resolution_m: float,
    name: str = "cloud",
    xyz: ArrayLike = (0.0, 0.0, 0.0),
    rpy: ArrayLike = (0.0, 0.0, 0.0),
) -> list[Obstacle]:
    """A point cloud's occupied voxels, one ``voxels`` obstacle a block (module docstring).

    Args:
        points: ``(N, 3)`` points in the cloud's frame [m].
        resolution_m: the voxels' side [m].
        name: the cloud's name; its blocks are ``NAME.k``, or ``NAME`` if there is one (a
            scene written back block by block reads as the same obstacles).
        xyz: the cloud frame's position in the world [m].
        rpy: its orientation, roll, pitch, yaw about fixed axes [rad].

    Raises:
        ObstacleError: bad points, a resolution outside :data:`RESOLUTION_RANGE_M`.
    """
    checked, resolution_m = checked_voxels(points, resolution_m, f"point cloud '{name}'")
    blocks = voxel_blocks(voxel_centres(checked, resolution_m))
    names = [name] if len(blocks) == 1 else [f"{name}.{k}" for k in range(len(blocks))]
    return [
        Obstacle(
            shape="voxels",
            points=block,
            resolution=resolution_m,
            xyz=np.asarray(xyz, dtype=float),
            rpy=np.asarray(rpy, dtype=float),
            name=block_name,
        )
        for block_name, block in zip(names, blocks, strict=True)
    ]


def sampled_surfaces(obstacles: Sequence[Obstacle], count: int, seed: int) -> FloatArray:
    """``(count, 3)`` points drawn on the obstacles' surfaces in the world, by area [m] (trimesh).

    What a depth camera would see of them, seen from everywhere: to try a scene as a cloud.
    """
    import trimesh

    meshes = []
    for obstacle in obstacles:
        radius, length = float(obstacle.radius or 0.0), float(obstacle.length or 0.0)
        if obstacle.shape == "box":
            mesh = trimesh.creation.box(extents=np.asarray(obstacle.size))
        elif obstacle.shape == "sphere":
            mesh = trimesh.creation.icosphere(subdivisions=4, radius=radius)
        elif obstacle.shape == "cylinder":
            mesh = trimesh.creation.cylinder(radius=radius, height=length, sections=64)
        elif obstacle.shape == "capsule":
            mesh = trimesh.creation.capsule(radius=radius, height=length)
        elif obstacle.shape == "mesh":
            loaded: Any = trimesh.load(str(obstacle.mesh), force="mesh")
            mesh = trimesh.Trimesh(vertices=loaded.vertices * obstacle.scale, faces=loaded.faces)
        else:
            raise ObstacleError(f"obstacle '{obstacle.name}': a {obstacle.shape} has no surface to sample")
        mesh.apply_transform(np.asarray(obstacle.placement.homogeneous))
        meshes.append(mesh)
    areas = np.array([mesh.area for mesh in meshes])
    counts = np.round(count * areas / areas.sum()).astype(int)
    parts = [
        trimesh.sample.sample_surface(m, int(n), seed=seed + k)[0]
        for k, (m, n) in enumerate(zip(meshes, counts, strict=True))
    ]
    return np.asarray(np.vstack(parts), dtype=float)
