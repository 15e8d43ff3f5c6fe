"""A MoveIt planning scene's collision objects as scene-file obstacles.

MoveIt's conventions (``shape_msgs/SolidPrimitive``): a box's ``dimensions`` are its side
lengths ``[x, y, z]``; a sphere's ``[radius]``; a cylinder's and a cone's ``[height, radius]``,
along their local z, centred. A primitive's pose is relative to its object's ``pose`` (when
given, as since MoveIt 1.1), which is in the frame its header names.

Boxes, spheres and cylinders become obstacles of the same shape. A cone becomes a mesh: a
pyramid of :data:`CONE_SIDES` sides circumscribing it (it contains the cone, so a clearance
to it is at most the clearance to the cone). A ``shape_msgs/Mesh`` becomes a mesh file. Planes,
prisms and operations other than ``ADD`` are refused, naming the object.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin
import trimesh

from cpr_kin.common.names import unprintable
from cpr_kin.shapes.obstacle_ranges import MAX_COORDINATE_M, MAX_NAME_CHARS, SIZE_RANGE_M
from planning.io.moveit_messages import CollisionObject, Mesh, MoveItImportError
from planning.io.moveit_poses import Pose

CONE_SIDES = 32
"""Sides of the pyramid that stands for a cone."""
PRIMITIVE_TYPES = {1: "box", 2: "sphere", 3: "cylinder", 4: "cone", 5: "prism"}
"""``SolidPrimitive.type`` numbers and names."""
ADD_OPERATIONS = (0, "0", "ADD", "add")


@dataclass(frozen=True)
class ConvertedObject:
    """One collision object's obstacles.

    Attributes:
        obstacles: scene-file obstacle entries; a mesh's ``mesh`` key names a key of ``meshes``.
        meshes: mesh files to write beside the scene, by file name.
    """

    obstacles: tuple[dict[str, Any], ...]
    meshes: dict[str, trimesh.Trimesh]


def placement(transform: np.ndarray) -> dict[str, list[float]]:
    """``xyz`` [m] and ``rpy`` [rad] of a ``(4, 4)`` transform, as a scene file places a shape."""
    return {
        "xyz": [float(v) for v in transform[:3, 3]],
        "rpy": [float(v) for v in pin.rpy.matrixToRpy(transform[:3, :3])],
    }


def _kind(value: int | str, where: str) -> str:
    kind = PRIMITIVE_TYPES.get(value) if isinstance(value, int) else str(value).lower()
    if kind not in ("box", "sphere", "cylinder", "cone", "prism"):
        raise MoveItImportError(f"{where}.type = {value!r}; allowed: 1-5 or {list(PRIMITIVE_TYPES.values())}")
    return kind


def mesh_file(name: str) -> str:
    """A file name for the mesh of obstacle ``name``: no folder, no hidden file (``../x`` is ``x``)."""
    return (re.sub(r"[^A-Za-z0-9_.-]", "_", name).lstrip(".") or "mesh") + ".stl"


def cone_mesh(height_m: float, radius_m: float) -> trimesh.Trimesh:
    """A pyramid of :data:`CONE_SIDES` sides around a cone of ``height_m`` and base ``radius_m``, centred."""
    circumscribed = radius_m / math.cos(math.pi / CONE_SIDES)
    angles = 2 * math.pi * np.arange(CONE_SIDES) / CONE_SIDES
    base = np.column_stack([circumscribed * np.cos(angles), circumscribed * np.sin(angles)])
    vertices = np.vstack([np.column_stack([base, np.full(CONE_SIDES, -height_m / 2)]), [0, 0, height_m / 2]])
    hull: trimesh.Trimesh = trimesh.convex.convex_hull(vertices)
    return hull


def _primitive(
    dimensions: list[float], kind: str, where: str, name: str, meshes: dict[str, trimesh.Trimesh]
) -> dict[str, Any]:
    needed = {"box": 3, "sphere": 1, "cylinder": 2, "cone": 2}
    if kind == "prism":
        raise MoveItImportError(
            f"{where}: prisms are not supported (boxes, spheres, cylinders, cones, meshes)"
        )
    meaning = "[x, y, z]" if kind == "box" else "[radius]" if kind == "sphere" else "[height, radius]"
    if len(dimensions) != needed[kind]:
        raise MoveItImportError(
            f"{where}.dimensions = {dimensions}: a {kind} needs {needed[kind]} ({meaning})"
        )
    low, high = SIZE_RANGE_M
    for k, value in enumerate(dimensions):
        if not low <= value <= high:
            raise MoveItImportError(
                f"{where}.dimensions[{k}] = {value!r}: a {kind}'s {meaning} must each be "
                f"in [{low:g}, {high:g}] m"
            )
    if kind == "box":
        return {"shape": "box", "size": list(dimensions)}
    if kind == "sphere":
        return {"shape": "sphere", "radius": dimensions[0]}
    if kind == "cylinder":
        return {"shape": "cylinder", "radius": dimensions[1], "length": dimensions[0]}
    file = mesh_file(name)
    meshes[file] = cone_mesh(dimensions[0], dimensions[1])
    return {"shape": "mesh", "mesh": file, "convex": True}


def _mesh(mesh: Mesh, where: str, name: str, meshes: dict[str, trimesh.Trimesh]) -> dict[str, Any]:
    vertices = np.array(mesh.vertices, dtype=float).reshape(-1, 3)
    faces = np.array([t.vertex_indices for t in mesh.triangles], dtype=int).reshape(-1, 3)
    if len(faces) == 0 or faces.min() < 0 or faces.max() >= len(vertices):
        raise MoveItImportError(
            f"{where}: {len(faces)} triangles over {len(vertices)} vertices; "
            "a mesh needs triangles whose indices name its vertices"
        )
    file = mesh_file(name)
    meshes[file] = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    return {"shape": "mesh", "mesh": file, "convex": True}


def convert_object(obj: CollisionObject, where: str, frame_in_base: np.ndarray) -> ConvertedObject:
    """The obstacles of ``obj``, placed in the robot's base frame (``frame_in_base``: its header's frame).

    Raises:
        MoveItImportError: an operation other than ADD, planes, a prism, a wrong dimension count.
    """
    if not obj.id or len(obj.id) > MAX_NAME_CHARS - 4 or unprintable(obj.id) is not None:
        raise MoveItImportError(
            f"{where}.id must be 1-{MAX_NAME_CHARS - 4} printable characters: every object needs an id, "
            "which names its obstacles"
        )
    if obj.operation not in ADD_OPERATIONS:
        raise MoveItImportError(
            f"{where}.operation = {obj.operation!r}; only ADD (0) objects can be imported"
        )
    if obj.planes:
        raise MoveItImportError(f"{where}: planes are not supported (an infinite plane has no clearance)")
    if len(obj.primitive_poses) != len(obj.primitives) or len(obj.mesh_poses) != len(obj.meshes):
        raise MoveItImportError(
            f"{where}: {len(obj.primitives)} primitives with {len(obj.primitive_poses)} poses, "
            f"{len(obj.meshes)} meshes with {len(obj.mesh_poses)} poses; one pose each"
        )
    object_in_base = frame_in_base @ (obj.pose or Pose()).matrix()
    parts: list[tuple[dict[str, Any], Pose]] = []
    meshes: dict[str, trimesh.Trimesh] = {}
    names = obstacle_names(obj)
    for k, (primitive, pose) in enumerate(zip(obj.primitives, obj.primitive_poses, strict=True)):
        kind = _kind(primitive.type, f"{where}.primitives[{k}]")
        parts.append(
            (_primitive(primitive.dimensions, kind, f"{where}.primitives[{k}]", names[k], meshes), pose)
        )
    for k, (mesh, pose) in enumerate(zip(obj.meshes, obj.mesh_poses, strict=True)):
        name = names[len(obj.primitives) + k]
        parts.append((_mesh(mesh, f"{where}.meshes[{k}]", name, meshes), pose))
    obstacles = []
    for k, (name, (entry, pose)) in enumerate(zip(names, parts, strict=True)):
        placed = placement(object_in_base @ pose.matrix())
        if not max(map(abs, placed["xyz"])) <= MAX_COORDINATE_M:
            part = f"primitives[{k}]" if k < len(obj.primitives) else f"meshes[{k - len(obj.primitives)}]"
            raise MoveItImportError(
                f"{where}.{part}: placed at {[round(v, 3) for v in placed['xyz']]} m in the robot's base "
                f"frame; a scene's coordinates are within +-{MAX_COORDINATE_M:g} m"
            )
        obstacles.append({"name": name, **entry, **placed})
    return ConvertedObject(obstacles=tuple(obstacles), meshes=meshes)


def obstacle_names(obj: CollisionObject) -> list[str]:
    """The names of the obstacles ``obj`` makes: its id for one shape, ``<id>_<k>`` for several."""
    count = len(obj.primitives) + len(obj.meshes)
    return [obj.id if count == 1 else f"{obj.id}_{k}" for k in range(count)]
