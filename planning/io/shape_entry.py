"""Shapes in a scene file: obstacles and payloads, their schema and their objects, both ways.

```yaml
obstacles:
  - {shape: box, size: [0.2, 0.3, 0.4], xyz: [0.5, 0.0, 0.2], rpy: [0, 0, 0.3]}
  - {shape: mesh, mesh: meshes/part.stl, scale: 0.001, convex: true, xyz: [0.4, 0.2, 0.0]}
  - {name: part, shape: box, size: [0.04, 0.04, 0.04], xyz: [0.3, 0.2, 0.02], touch_links: [finger]}
payload: {mass_kg: 1.5, com_in_tcp: [0, 0, 0.05], shape: {shape: sphere, radius: 0.04, xyz: [0, 0, 0.05]}}
```
"""

import dataclasses
from pathlib import Path
from typing import Annotated, Any, Literal, Self

import numpy as np
from pydantic import Field, model_validator

import cpr_kin as ck
from cpr_kin.kinematics.dynamics import MAX_COM_OFFSET_M, MAX_PAYLOAD_KG, PAYLOAD_NAME
from cpr_kin.shapes.obstacle_ranges import SCALE_RANGE
from planning.io.cloud_entry import PointCloudSpec
from planning.io.schema_types import FilePath, Name, Point, Size, Strict, Turn, between, empty_list


class _Placed(Strict):
    name: Name | None = None
    xyz: Point
    rpy: Turn = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    touch_links: Annotated[list[Name], Field(max_length=64)] = Field(default_factory=empty_list)


class BoxSpec(_Placed):
    """``{shape: box, size: [x, y, z], xyz, rpy}``: full side lengths [m]."""

    shape: Literal["box"]
    size: Annotated[list[Size], Field(min_length=3, max_length=3)]


class SphereSpec(_Placed):
    """``{shape: sphere, radius, xyz}`` [m]."""

    shape: Literal["sphere"]
    radius: Size


class CylinderSpec(_Placed):
    """``{shape: cylinder, radius, length, xyz, rpy}``: axis along the local z [m]."""

    shape: Literal["cylinder"]
    radius: Size
    length: Size


class CapsuleSpec(_Placed):
    """``{shape: capsule, radius, length, xyz, rpy}``: segment along the local z [m]."""

    shape: Literal["capsule"]
    radius: Size
    length: Size


class MeshSpec(_Placed):
    """``{shape: mesh, mesh: FILE, scale, convex, xyz, rpy}``; FILE relative to the scene."""

    shape: Literal["mesh"]
    mesh: FilePath
    scale: Annotated[float, between(*SCALE_RANGE)] = 1.0
    convex: bool = True


ObstacleSpec = Annotated[
    BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec | PointCloudSpec,
    Field(discriminator="shape"),
]


Moment = Annotated[float, between(-1e3, 1e3)]
PayloadShapeSpec = Annotated[
    BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec, Field(discriminator="shape")
]
"""A payload's collision shape: an obstacle's box, sphere, cylinder, capsule or mesh (its convex
hull), in its frame."""


class PayloadSpec(Strict):
    """The ``payload:`` block, an attached object: its mass and its shape; see :class:`cpr_kin.Payload`."""

    name: Name | None = None
    mass_kg: Annotated[float, between(0.0, MAX_PAYLOAD_KG)] = 0.0
    com_in_tcp: Annotated[
        list[Annotated[float, between(-MAX_COM_OFFSET_M, MAX_COM_OFFSET_M)]],
        Field(min_length=3, max_length=3),
    ] = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    inertia: (
        Annotated[list[Moment], Field(min_length=3, max_length=3)]
        | Annotated[
            list[Annotated[list[Moment], Field(min_length=3, max_length=3)]],
            Field(min_length=3, max_length=3),
        ]
        | None
    ) = None
    frame: Name | None = None
    shape: PayloadShapeSpec | None = None
    touch_links: Annotated[list[Name], Field(max_length=64)] = Field(default_factory=empty_list)
    touch_obstacles: Annotated[list[Name], Field(max_length=64)] = Field(default_factory=empty_list)

    @model_validator(mode="after")
    def _links_once(self) -> Self:
        if self.shape is not None and self.shape.touch_links:
            raise ValueError("the links a payload may touch are its own 'touch_links', not its shape's")
        return self

    def payload(self, shape: "ck.Obstacle | None") -> "ck.Payload":
        """The :class:`cpr_kin.Payload` with ``shape`` built from :attr:`shape`.

        Raises:
            cpr_kin.CprKinError: an unphysical inertia.
        """
        inertia = None
        if self.inertia is not None:
            inertia = np.diag(self.inertia) if np.ndim(self.inertia) == 1 else np.array(self.inertia)
        return ck.Payload(
            self.mass_kg,
            (self.com_in_tcp[0], self.com_in_tcp[1], self.com_in_tcp[2]),
            None if inertia is None else tuple(tuple(row) for row in inertia.tolist()),
            self.frame,
            shape,
            tuple(self.touch_links),
            self.name or PAYLOAD_NAME,
            tuple(self.touch_obstacles),
        )


def obstacle_of(
    item: BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec, name: str, base: Path
) -> "ck.Obstacle":
    """The obstacle (or payload shape) of a validated entry; a mesh relative to ``base``.

    Raises:
        cpr_kin.CprKinError: a shape coal cannot build, a mesh that cannot be read.
    """
    links = tuple(item.touch_links)
    if isinstance(item, BoxSpec):
        obstacle = ck.Obstacle.box(item.size, item.xyz, item.rpy, name=name)
    elif isinstance(item, SphereSpec):
        obstacle = ck.Obstacle.sphere(item.radius, item.xyz, name=name)
    elif isinstance(item, CylinderSpec):
        obstacle = ck.Obstacle.cylinder(item.radius, item.length, item.xyz, item.rpy, name=name)
    elif isinstance(item, CapsuleSpec):
        obstacle = ck.Obstacle.capsule(item.radius, item.length, item.xyz, item.rpy, name=name)
    else:
        mesh = (base / item.mesh).resolve()  # absolute: the scene may be planned elsewhere
        obstacle = ck.Obstacle.from_mesh(mesh, item.xyz, item.rpy, item.scale, item.convex, name=name)
        obstacle.geometry()  # read the file now: a broken mesh is a scene error
    return dataclasses.replace(obstacle, touch_links=links) if links else obstacle


def obstacle_to_dict(obstacle: "ck.Obstacle") -> dict[str, Any]:
    """An obstacle in the scene file's form (docs/formats.md)."""
    entry: dict[str, Any] = {"name": obstacle.name, "shape": obstacle.shape}
    if obstacle.shape == "box":
        entry["size"] = np.asarray(obstacle.size).tolist()
    if obstacle.shape in ("sphere", "cylinder", "capsule"):
        entry["radius"] = obstacle.radius
    if obstacle.shape in ("cylinder", "capsule"):
        entry["length"] = obstacle.length
    if obstacle.shape == "mesh":
        entry.update(mesh=str(obstacle.mesh), scale=obstacle.scale, convex=obstacle.convex)
    if obstacle.shape == "voxels":  # the voxel centres: they read back as the same voxels
        entry.update(
            shape="point_cloud", points=np.asarray(obstacle.points).tolist(), resolution=obstacle.resolution
        )
    entry.update(xyz=obstacle.xyz.tolist(), rpy=obstacle.rpy.tolist())
    if obstacle.touch_links:
        entry["touch_links"] = list(obstacle.touch_links)
    return entry


def payload_to_dict(payload: "ck.Payload") -> dict[str, Any]:
    """A payload in the scene file's form (docs/formats.md)."""
    entry: dict[str, Any] = {} if payload.name == PAYLOAD_NAME else {"name": payload.name}
    entry |= {"mass_kg": payload.mass_kg, "com_in_tcp": list(payload.com_in_frame_m)}
    if payload.inertia_kg_m2 is not None:
        entry["inertia"] = [list(row) for row in payload.inertia_kg_m2]
    if payload.frame is not None:
        entry["frame"] = payload.frame
    if payload.shape is not None:
        entry["shape"] = {k: v for k, v in obstacle_to_dict(payload.shape).items() if k != "name"}
    if payload.touch_links:
        entry["touch_links"] = list(payload.touch_links)
    if payload.touch_obstacles:
        entry["touch_obstacles"] = list(payload.touch_obstacles)
    return entry
