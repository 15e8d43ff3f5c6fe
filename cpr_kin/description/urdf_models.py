"""Pinocchio's models of a prepared URDF: kinematic and collision now, the visual one on first use.

Every mesh of the collision model becomes its convex hull (:func:`convex_hulls`), which
contains it: a clearance to the hull is at most the clearance to the mesh (safe), and coal
gives signed distances between convex shapes. A hull coal cannot hold becomes the mesh's
bounding capsule, which contains it as well. The meshes are kept: where a shape reaches far
beyond its mesh, the mesh decides (:mod:`cpr_kin.shapes.exact_meshes`).
"""

from __future__ import annotations

import contextlib
import os
import re
import sys
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin
from lxml import etree

from cpr_kin.bounds.capsule_fit import frame_about
from cpr_kin.bounds.pair_bounds import bounding_capsule
from cpr_kin.common.errors import UrdfError
from cpr_kin.description.geometry_cache import geometry_model, mesh_hull
from cpr_kin.description.supported import MAX_SHAPE_M
from cpr_kin.shapes.mesh_geometry import spans_volume

if TYPE_CHECKING:  # what a robot whose links are meshes imports, where it has one
    from cpr_kin.shapes.exact_meshes import MeshSource

MIN_MESH_SPAN_M = 1e-6
"""Smallest largest extent of a link mesh [m], scale applied: a mesh smaller than a micrometre
(a scale of 0, or 1e-9) is no part of an arm, and its points merge into one at the hull's
tolerance (trimesh's 1e-8 m)."""


@contextlib.contextmanager
def captured_stderr() -> Iterator[list[str]]:
    """Capture what native code writes to the process's standard error (file descriptor 2).

    Pinocchio's URDF parser (urdfdom) prints its complaints there, e.g. "Error: Material
    [grey] color has no rgba", about details the planner does not use. Within the context
    they go to a temporary file instead of the user's terminal; the yielded list holds its
    lines once the context ends, for a caller that wants to report them in its own words.
    """
    lines: list[str] = []
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as sink:
        os.dup2(sink.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            lines.extend(sink.read(10_000).decode("utf-8", errors="replace").splitlines())


def build_models(xml: str, path: Path, kind: Any = pin.GeometryType.COLLISION) -> tuple[Any, Any]:
    """Pinocchio's kinematic model and the ``kind`` geometry model of the prepared URDF text.

    Raises:
        UrdfError: Pinocchio cannot build them, a mesh file cannot be read, or a mesh is not
            finite, reaches too far or spans too little (:func:`check_meshes`).
    """
    try:
        with captured_stderr() as complaints:  # urdfdom prints to fd 2; a model that builds needs none
            model = pin.buildModelFromXML(xml)
            geometry = geometry_model(model, xml, kind)
    except Exception as exc:  # Pinocchio reports C++ exceptions as RuntimeError/ValueError
        unread = re.search(r"Could not load resource (.+?)\s*(?:\n|$)", str(exc))
        if unread is not None:  # coal's loader names its own source file; the link is what helps
            raise UrdfError(_unreadable_mesh(xml, path, unread.group(1))) from None
        said = " ".join(line.strip() for line in complaints[:2])
        raise UrdfError(f"Pinocchio cannot build a model from '{path}': {exc} {said}".strip()) from None
    check_meshes(model, geometry, path)
    return model, geometry


def check_meshes(model: Any, geometry: Any, path: Path) -> None:
    """Refuse a mesh of ``geometry`` that is not finite, reaches too far or spans too little.

    A vertex not finite, one beyond :data:`MAX_SHAPE_M` of the link's frame, or a mesh whose
    largest extent is below :data:`MIN_MESH_SPAN_M`: coal would take such a mesh and crash on its
    hull (a segmentation fault at an infinite vertex), compute with nonsense, or merge its points
    into one. The message names the link, the file and the vertex or the extent.

    Raises:
        UrdfError: the first such mesh.
    """
    for obj in geometry.geometryObjects:
        if not isinstance(obj.geometry, coal.BVHModelBase):
            continue
        vertices = np.asarray(obj.geometry.vertices(), dtype=float).reshape(-1, 3)
        if not vertices.size:
            continue
        finite = np.isfinite(vertices).all(axis=1)
        reach = np.where(finite, np.linalg.norm(np.where(finite[:, None], vertices, 0.0), axis=1), np.inf)
        span = float(np.ptp(vertices, axis=0).max()) if finite.all() else np.inf
        if reach.max() <= MAX_SHAPE_M and span >= MIN_MESH_SPAN_M:
            continue
        link = model.frames[obj.parentFrame].name if obj.parentFrame < len(model.frames) else obj.name
        what = f"URDF '{path}': link '{link}': mesh '{obj.meshPath}'"
        worst = int(np.argmax(reach))
        vertex = ", ".join(f"{v:.6g}" for v in vertices[worst])
        if not finite[worst]:
            raise UrdfError(
                f"{what} has a vertex that is not finite: vertex {worst} = ({vertex}); fix the mesh file"
            )
        if span < MIN_MESH_SPAN_M:
            raise UrdfError(
                f"{what} spans {span:.3g} m (its largest extent, scale applied), below "
                f"{MIN_MESH_SPAN_M:g} m; check the scale in its <mesh>"
            )
        raise UrdfError(
            f"{what} reaches {reach[worst]:.6g} m from its link's frame at vertex {worst} = ({vertex}) m, "
            f'beyond {MAX_SHAPE_M:g} m; a mesh drawn in millimetres needs scale="0.001 0.001 0.001" '
            "in its <mesh>"
        )


JOINT_SUFFIX = "\x00joint"
"""Appended to a joint's name while Pinocchio reduces a model (:func:`reduced_models`): no URDF
name holds a NUL."""


JOINT_FRAMES = (pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT)
"""The frame types of a URDF's joints (a locked joint's frame is a fixed one in the reduced model)."""


def reduced_models(model: Any, geometries: list[Any], locked: list[int], q_ref: Any) -> tuple[Any, list[Any]]:
    """Pinocchio's ``buildReducedModel``: ``model`` with its ``locked`` joints fixed at ``q_ref``.

    Also where a joint and a link share a name (ANYmal's ``LF_HAA``, the B1-Z1's fixed
    ``gripperStator``, as URDF allows: joints and links are named apart). Pinocchio's reduction
    looks frames up by name alone and refuses two ("Several frames match the filter"); the
    joints' names are made distinct while it reduces and given back after.
    """
    links = {frame.name for frame in model.frames if frame.type == pin.FrameType.BODY}
    shared = {frame.name for frame in model.frames if frame.type in JOINT_FRAMES and frame.name in links}
    if shared:
        model = model.copy()
        _rename(model, lambda name: name + JOINT_SUFFIX if name in shared else name)
    reduced, reduced_geometries = pin.buildReducedModel(model, geometries, locked, q_ref)
    if shared:
        _rename(reduced, lambda name: name.removesuffix(JOINT_SUFFIX))
    return reduced, list(reduced_geometries)


def _rename(model: Any, renamed: Callable[[str], str]) -> None:
    """Rename ``model``'s joints, in ``model.names`` and their joints' frames, by ``renamed``, in place."""
    for index, name in enumerate(model.names):
        model.names[index] = renamed(name)
    for index, frame in enumerate(model.frames):
        if frame.type in JOINT_FRAMES and renamed(frame.name) != frame.name:
            changed = model.frames[index]
            changed.name = renamed(frame.name)
            model.frames[index] = changed


def _unreadable_mesh(xml: str, path: Path, mesh: str) -> str:
    """The message for a mesh file coal (assimp) cannot read: the link, the file, the formats."""
    root = etree.fromstring(xml.encode(), etree.XMLParser(resolve_entities=False, no_network=True))
    links = [
        link.get("name", "")
        for link in root.findall("link")
        if any(m.get("filename") == mesh for m in link.iter("mesh"))
    ]
    named = f"link '{links[0]}': " if links else ""
    return (
        f"URDF '{path}': {named}mesh '{mesh}' is not a mesh file coal can read "
        "(STL, OBJ, DAE, PLY, ... as assimp reads them); give a mesh file, or fix its path"
    )


@dataclass(frozen=True)
class VisualModel:
    """Builds the visual geometry model of a prepared URDF, with the held joints locked as loaded.

    Attributes:
        xml: the prepared URDF text (mesh paths resolved).
        path: the URDF file, for messages.
        locked: Pinocchio ids of the held joints in the full model.
        q_ref: the full model's configuration the held joints are locked at.
    """

    xml: str
    path: Path
    locked: tuple[int, ...] = ()
    q_ref: tuple[float, ...] = ()

    def __call__(self) -> Any:
        """The visual geometry model, reduced to the planned joints."""
        model, visual = build_models(self.xml, self.path, pin.GeometryType.VISUAL)
        if self.locked:
            _, (visual,) = reduced_models(model, [visual], list(self.locked), np.array(self.q_ref))
        return visual


def convex_hulls(collision: Any) -> tuple[MeshSource, ...]:
    """Replace every mesh of ``collision`` by its convex hull (module docstring).

    coal's convex shapes give a vertex at most 255 neighbours. A hull whose triangles put
    more around a vertex (a fine fan, as Centauro's pelvis has: 566) is built of polygons
    instead (qhull's merged facets, the same hull); one whose polygons still do (a cone's
    apex), and a flat mesh, whose hull has no volume (coal's Qhull would crash on it,
    :func:`~cpr_kin.shapes.mesh_geometry.spans_volume`), is replaced by the mesh's bounding
    capsule (:func:`cpr_kin.bounds.pair_bounds.bounding_capsule`), which contains it too.

    Returns:
        Each replaced mesh (:class:`~cpr_kin.shapes.exact_meshes.MeshSource`), in geometry order;
        ``hull`` false where a capsule replaced it.
    """
    sources = []
    for index, obj in enumerate(collision.geometryObjects):
        geometry = obj.geometry
        if not isinstance(geometry, coal.BVHModelBase):
            continue
        from cpr_kin.shapes.exact_meshes import MeshSource

        scale = tuple(float(s) for s in obj.meshScale)
        flat = not spans_volume(np.asarray(geometry.vertices(), dtype=float))
        for keep_triangles, qhull_options in () if flat else ((True, "Qt"), (False, "Qx")):
            try:
                obj.geometry = mesh_hull(geometry, keep_triangles, qhull_options)  # kept on disk
            except RuntimeError:  # "Too many neighbors."
                continue
            sources.append(MeshSource(index, geometry, pin.SE3.Identity(), obj.meshPath, scale))
            break
        else:
            obj.geometry, in_geometry = _capsule(geometry)
            obj.placement = obj.placement * in_geometry
            sources.append(
                MeshSource(index, geometry, in_geometry.inverse(), obj.meshPath, scale, hull=False)
            )
    return tuple(sources)


def _capsule(mesh: Any) -> tuple[Any, Any]:
    """The bounding capsule of ``mesh`` (a coal shape) and its placement in the mesh's frame."""
    ends, radius = bounding_capsule(mesh)
    axis = ends[1] - ends[0]
    length = float(np.linalg.norm(axis))
    rotation = frame_about(axis) if length > 0.0 else np.eye(3)
    shape = coal.Capsule(radius, length) if length > 0.0 else coal.Sphere(radius)
    return shape, pin.SE3(rotation, ends.mean(axis=0))
