"""Pinocchio's geometry model of a URDF whose links are meshes, built once and kept on disk.

Building a geometry model reads every mesh file (coal's assimp loader) and builds coal's tree
of bounding volumes over its triangles: most of a robot's load where its meshes are fine
(MotionBenchMaker's UR5 with its Robotiq gripper and force sensor, two meshes of 40,000
triangles each: 0.4 s of every load, in every new process). Pinocchio's binary archive of the
built model reads back several times faster, its trees included. So the model is kept under
``$CPR_FIREFLY_CACHE/geometry-models/`` (:mod:`cpr_kin.common.disk_cache`), named by a digest of
everything it is built from: the prepared URDF's text, the model's kind (collision or visual),
every mesh file's path and bytes, and Pinocchio's and coal's versions. The files are large (the
trees: about 60 MB for that UR5, 220 MB for example-robot-data's SO-101), so they are kept up to
:data:`KEPT_BYTES` in all, the least recently used removed.

Each mesh's convex hull (coal's Qhull, which the collision model holds in the mesh's place:
:func:`~cpr_kin.description.urdf_models.convex_hulls`) is kept too, under ``mesh-hulls/``, named
by the mesh's vertices and Qhull's options (:func:`mesh_hull`): the SO-101's fine meshes took
0.25 s of Qhull in every load.

A kept model is read only where it fits: the archive reads whole (one cut short or damaged
raises in Pinocchio's reader) and holds, in the URDF's order, one object per link geometry of
the kind, each on its link's frame. Otherwise, and for a URDF without meshes (nothing slow to
build), the model is built as before.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
from lxml import etree

from cpr_kin.common.disk_cache import keep_file, kept_file

HULL_BYTES = 256 << 20
"""The hulls kept on disk add up to this at most [bytes] (a robot's are a few MB)."""
KEPT_BYTES = 1 << 30
"""The geometry models kept on disk add up to this at most [bytes] (several robots, or one robot's
collision and visual models; a new version of the libraries or of a robot's files makes new ones)."""
FORMAT = b"geometry-model-1"
"""Named in the digest: a change to what is kept makes the models anew."""
_TAGS = {pin.GeometryType.COLLISION: "collision", pin.GeometryType.VISUAL: "visual"}


def geometry_model(model: Any, xml: str, kind: Any) -> Any:
    """The ``kind`` geometry model of the prepared URDF text ``xml`` for ``model``: kept, or built and kept.

    ``pinocchio.buildGeomFromUrdfString(model, xml, kind)``'s model either way (module
    docstring). Its exceptions (a mesh it cannot read) are the caller's.
    """
    links = _link_geometries(xml, _TAGS[kind])
    names = [link for link, _ in links]
    meshes = [mesh for _, shape in links for mesh in shape.iter("mesh")]
    digest = _digest(xml, kind, [mesh.get("filename") or "" for mesh in meshes]) if meshes else None
    if digest is None:
        return pin.buildGeomFromUrdfString(model, xml, kind)
    name = f"{digest}.bin"
    kept = _read(kept_file("geometry-models", name), pin.GeometryModel())
    if kept is not None and _fits(kept, model, names):
        return kept
    built = pin.buildGeomFromUrdfString(model, xml, kind)
    if _fits(built, model, names):  # else it would never be read: not kept
        keep_file("geometry-models", name, lambda partial: built.saveToBinary(str(partial)), KEPT_BYTES)
    return built


def _link_geometries(xml: str, tag: str) -> list[tuple[str, Any]]:
    """``(link, <geometry>)`` of every ``tag`` (collision or visual) element, in the URDF's order."""
    root = etree.fromstring(xml.encode(), etree.XMLParser(resolve_entities=False, no_network=True))
    found = []
    for link in root.findall("link"):
        for element in link.findall(tag):
            shape = element.find("geometry")
            if shape is not None and len(shape):
                found.append((link.get("name", ""), shape))
    return found


def _digest(xml: str, kind: Any, files: list[str]) -> str | None:
    """What the model is built from, hashed; ``None`` where a mesh file cannot be read (the builder says)."""
    digest = hashlib.sha256(FORMAT + xml.encode() + str(kind).encode())
    digest.update(f"pinocchio {pin.__version__} coal {coal.__version__}".encode())
    for file in dict.fromkeys(files):
        try:
            with Path(file).open("rb") as stream:  # in pieces: a mesh file may be large
                body = hashlib.file_digest(stream, "sha256").digest()
        except OSError:
            return None
        digest.update(file.encode() + b"\0" + body)
    return digest.hexdigest()


def _read(path: Path | None, empty: Any) -> Any | None:
    """``empty`` (a Pinocchio or coal object) read from its binary archive at ``path``, if it reads whole."""
    if path is None:
        return None
    try:
        empty.loadFromBinary(str(path))
    except (RuntimeError, MemoryError, OSError):  # cut short, damaged, removed meanwhile
        return None
    return empty


def _fits(kept: Any, model: Any, links: list[str]) -> bool:
    """Whether ``kept`` holds one object per geometry of ``links``, each on its link's frame."""
    frames = model.frames
    objects = kept.geometryObjects
    on_frames = [frames[o.parentFrame].name if 0 <= o.parentFrame < len(frames) else "" for o in objects]
    return sorted(on_frames) == sorted(links)


def mesh_hull(bvh: Any, keep_triangles: bool, qhull_options: str) -> Any:
    """The convex hull of coal's triangle model ``bvh`` that ``bvh.buildConvexHull`` builds, kept on disk.

    A hull of triangles (a ``coal.Convex``) is kept; one of polygons (where a vertex has too
    many neighbours for triangles) is built each time. Qhull's ``RuntimeError`` is the caller's.
    """
    vertices = np.ascontiguousarray(bvh.vertices(), dtype=float)
    key = f"{FORMAT.decode()} coal {coal.__version__} {keep_triangles} {qhull_options}".encode()
    name = hashlib.sha256(key + vertices.tobytes()).hexdigest() + ".bin"
    kept = _read(kept_file("mesh-hulls", name), coal.Convex()) if keep_triangles else None
    if kept is not None and kept.num_points > 0:
        return kept
    bvh.buildConvexHull(keep_triangles, qhull_options)
    hull = bvh.convex
    if isinstance(hull, coal.Convex):
        keep_file("mesh-hulls", name, lambda partial: hull.saveToBinary(str(partial)), HULL_BYTES)
    return hull
