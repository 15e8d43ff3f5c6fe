"""The exact triangle meshes of a robot's concave links, kept beside the convex shapes that bound them.

Every link mesh is checked as its convex hull (:func:`cpr_kin.description.urdf_models.convex_hulls`): it
contains the mesh, so what it accepts is clear, and coal measures it fast. A concave link's hull
fills its hollows (a UR forearm's by 40 mm) and refuses what the robot can do. Where a hull
reaches beyond its mesh by more than :data:`REFINED_ABOVE_M`, the hull is kept as a bound only
and the mesh decides wherever the hull comes within a margin (:mod:`cpr_kin.shapes.exact_pairs`);
elsewhere the hull is the model, within that much of the mesh.

A hull's excess (how far it reaches beyond the mesh) is sampled: the largest distance to the
mesh's triangles (coal's) of :data:`EXCESS_SAMPLES` points drawn by area on the hull's surface
(seeded). It is computed once per mesh file and scale and kept on disk
(:mod:`cpr_kin.common.disk_cache`). The sampled largest is below the true one by at most about the
samples' spacing; an excess taken too small only makes a margin test refuse where the mesh
might have passed (:mod:`cpr_kin.shapes.exact_pairs`), never accept what the mesh does not.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from cpr_kin.common.disk_cache import cached_json
from cpr_kin.shapes.mesh_pieces import convex_pieces
from cpr_kin.shapes.mesh_topology import mesh_topology
from cpr_kin.shapes.vertex_witness import VertexGroups, vertex_groups

FloatArray = NDArray[np.float64]

REFINED_ABOVE_M = 1e-3
"""A hull reaching beyond its mesh by more than this [m] is a bound, and the mesh decides."""
EXCESS_SAMPLES = 2_000
"""Points drawn on a hull's surface to measure its excess when a robot is loaded."""


@dataclass(frozen=True)
class MeshSource:
    """A link mesh that :func:`~cpr_kin.description.urdf_models.convex_hulls` replaced by a convex shape.

    Attributes:
        geometry: the geometry's index in the collision model.
        bvh: coal's triangle model of the mesh (a ``BVHModelOBBRSS``), in the mesh's frame.
        mesh_in_shape: the mesh's frame in the replacing shape's frame (identity for a hull;
            a bounding capsule is placed at the mesh's axis).
        path: the mesh file, with ``scale``, what the excess is cached by.
        hull: the shape is the mesh's convex hull (else its bounding capsule, whose excess is
            not measured: the mesh always decides).
    """

    geometry: int
    bvh: Any
    mesh_in_shape: Any
    path: str
    scale: tuple[float, ...]
    hull: bool = True


@dataclass(frozen=True)
class ExactMesh:
    """A link mesh that decides where its bounding shape comes within a margin.

    Attributes:
        geometry: its geometry's index in the robot's collision model.
        bvh: coal's triangle model, in the mesh's frame.
        mesh_in_shape: the mesh's frame in its geometry's (the bounding shape's) frame.
        excess_m: how far the bounding shape reaches beyond the mesh [m], sampled: a distance
            to the shape is about at most this much below the distance to the mesh (``inf``:
            not measured).
        triangles: ``(F, 3, 3)`` the mesh's triangles' corners, in the mesh's frame [m].
        piece_points: ``(K, 3)`` a vertex of each connected piece of the mesh [m], ``None``
            for more than :data:`~cpr_kin.shapes.mesh_topology.MAX_PIECES` pieces.
        hull_planes: ``(H, 4)`` the facets of the mesh's convex hull, ``n . x + d <= 0`` inside
            (unit ``n``, ``d`` [m]).
        corners: ``(V, 3)`` the triangles' corners, each once [m].
    """

    geometry: int
    bvh: Any = field(repr=False)
    mesh_in_shape: Any = field(repr=False)
    excess_m: float
    triangles: FloatArray = field(repr=False)
    piece_points: FloatArray | None = field(repr=False)
    hull_planes: FloatArray = field(repr=False)
    corners: FloatArray = field(repr=False)

    @cached_property
    def pieces(self) -> tuple[Any, ...]:
        """The convex pieces (coal's) whose union holds the triangles, in the mesh's frame.

        :mod:`~cpr_kin.shapes.mesh_pieces`, made or read from disk on first use.
        """
        return convex_pieces(self.triangles)

    @cached_property
    def vertex_groups(self) -> VertexGroups:
        """The mesh's corners, in its frame, grouped (:mod:`cpr_kin.shapes.vertex_witness`)."""
        return vertex_groups(self.corners)

    def holds(self, points_in_mesh: FloatArray) -> NDArray[np.bool_]:
        """``(M,)`` which of ``points_in_mesh`` ``(M, 3)`` [m] lie inside the mesh.

        By the generalised winding number (the solid angle the triangles subtend, Jacobson et
        al. 2013): about 1 inside a closed surface, 0 outside, whichever way it is oriented;
        a point counts as inside above one half, which tolerates small holes. A point outside
        the mesh's convex hull (its facets' planes) is outside without it.
        """
        points = np.ascontiguousarray(points_in_mesh, dtype=float)
        return np.asarray(_inside(self.triangles, self.hull_planes, points, np.eye(3), np.zeros(3), False))

    def holds_any(self, points: FloatArray, rotation: FloatArray, translation: FloatArray) -> bool:
        """Whether the mesh holds one of ``points`` ``(M, 3)`` [m], given in a frame placed in the mesh's.

        ``rotation`` ``(3, 3)`` and ``translation`` ``(3,)`` [m] place that frame in the mesh's:
        :meth:`holds` of the points moved there, ``.any()``, in one compiled call that stops at
        the first point inside (a pair test asks it for a few points, many times).
        """
        return bool(_inside(self.triangles, self.hull_planes, points, rotation, translation, True).any())


@njit
def _inside(
    triangles: FloatArray,
    planes: FloatArray,
    points: FloatArray,
    rotation: FloatArray,
    translation: FloatArray,
    first_only: bool,
) -> NDArray[np.bool_]:
    """``(M,)`` which of ``points``, rotated and translated, are inside (:meth:`ExactMesh.holds`).

    With ``first_only``, none after the first inside is tested (reported outside).
    """
    inside = np.zeros(points.shape[0], dtype=np.bool_)
    moved = np.empty((1, 3))
    for m in range(points.shape[0]):
        for i in range(3):
            moved[0, i] = (
                points[m, 0] * rotation[i, 0] + points[m, 1] * rotation[i, 1] + points[m, 2] * rotation[i, 2]
            ) + translation[i]
        in_hull = True  # outside a facet's plane of the convex hull: outside the mesh
        for h in range(planes.shape[0]):
            offset = moved[0, 0] * planes[h, 0] + moved[0, 1] * planes[h, 1] + moved[0, 2] * planes[h, 2]
            if offset + planes[h, 3] > 1e-9:
                in_hull = False
                break
        if in_hull and abs(_winding_numbers(triangles, moved)[0]) > 0.5:
            inside[m] = True
            if first_only:
                break
    return inside


@njit
def _winding_numbers(triangles: FloatArray, points: FloatArray) -> FloatArray:
    """``(M,)`` the winding number of the triangles ``(F, 3, 3)`` about each of ``points`` ``(M, 3)``.

    Van Oosterom and Strackee's solid angle of each triangle, summed over 4 pi.
    """
    found = np.zeros(points.shape[0])
    for m in range(points.shape[0]):
        total = 0.0
        for f in range(triangles.shape[0]):
            ax, ay, az = (
                triangles[f, 0, 0] - points[m, 0],
                triangles[f, 0, 1] - points[m, 1],
                triangles[f, 0, 2] - points[m, 2],
            )
            bx, by, bz = (
                triangles[f, 1, 0] - points[m, 0],
                triangles[f, 1, 1] - points[m, 1],
                triangles[f, 1, 2] - points[m, 2],
            )
            cx, cy, cz = (
                triangles[f, 2, 0] - points[m, 0],
                triangles[f, 2, 1] - points[m, 1],
                triangles[f, 2, 2] - points[m, 2],
            )
            la = math.sqrt(ax * ax + ay * ay + az * az)
            lb = math.sqrt(bx * bx + by * by + bz * bz)
            lc = math.sqrt(cx * cx + cy * cy + cz * cz)
            det = ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
            den = (
                la * lb * lc
                + (ax * bx + ay * by + az * bz) * lc
                + (bx * cx + by * cy + bz * cz) * la
                + (cx * ax + cy * ay + cz * az) * lb
            )
            total += math.atan2(det, den)
        found[m] = total / (2.0 * math.pi)
    return found


def exact_meshes(sources: Sequence[MeshSource], samples: int = EXCESS_SAMPLES) -> dict[int, ExactMesh]:
    """The meshes of ``sources`` their shapes exceed by more than :data:`REFINED_ABOVE_M`, by geometry."""
    found = {}
    for source in sources:
        excess = hull_excess(source, samples)["excess_m"] if source.hull else math.inf
        if excess > REFINED_ABOVE_M:
            made = mesh_topology(source.bvh, _content(source, b"faces-1"))
            found[source.geometry] = ExactMesh(
                source.geometry,
                source.bvh,
                source.mesh_in_shape,
                excess,
                made.triangles,
                made.piece_points,
                made.hull_planes,
                made.corners,
            )
    return found


def hull_excess(source: MeshSource, samples: int = EXCESS_SAMPLES, seed: int = 0) -> dict[str, float]:
    """How far the convex hull of ``source``'s mesh reaches beyond it, sampled (module docstring).

    Returns:
        ``excess_m``: the largest distance of a sampled hull point from the mesh [m];
        ``spacing_m``: the side of a square of the hull's area over ``samples`` [m], about how
        far below the true largest that may be.
    """
    digest = hashlib.sha256(_content(source, b"hull-excess-1")).hexdigest()

    def compute() -> dict[str, float]:
        import trimesh  # only a first load of a mesh needs it

        vertices = np.asarray(source.bvh.vertices(), dtype=float)
        hull = trimesh.Trimesh(vertices=vertices).convex_hull
        on_hull = trimesh.sample.sample_surface(hull, samples, seed=seed)[0]
        request, point, identity = coal.DistanceRequest(), coal.Sphere(1e-12), coal.Transform3s()
        largest = max(
            coal.distance(
                source.bvh, identity, point, coal.Transform3s(np.eye(3), p), request, coal.DistanceResult()
            )
            for p in on_hull
        )
        spacing = math.sqrt(float(hull.area) / samples)
        excess = max(0.0, float(largest))
        return {"excess_m": excess, "spacing_m": spacing}

    return cached_json("hull-excess", f"{digest}-{samples}-{seed}", compute)


def _content(source: MeshSource, what: bytes) -> bytes:
    """What a mesh's value ``what`` depends on: its file's bytes (its vertices where unreadable), scale."""
    try:
        body = Path(source.path).read_bytes()
    except OSError:
        body = np.asarray(source.bvh.vertices(), dtype=float).tobytes()
    return body + np.asarray(source.scale, dtype=float).tobytes() + what
