"""A vertex of a mesh within a margin of a primitive: a proof that the two are that close.

The exact meshes decide a pair where its convex shapes come within a margin
(:mod:`cpr_kin.shapes.exact_pairs`): coal's collision test descends the mesh's bounding-volume
tree to a pair of triangles within the margin. Where a gripper closes round a can, the mesh
wraps the obstacle, most of its volumes lie within the margin, and the descent takes
milliseconds before it finds one that is. The distance from any point of the mesh to the other
shape is at least the meshes' distance, so a vertex of the mesh closer than the margin to a
primitive (sphere, box, cylinder, capsule) proves the pair within it. Where no vertex is that
close, nothing is proven: coal decides.

The vertices are kept in groups, each in a ball (:class:`VertexGroups`). A distance to a
primitive changes no faster than the point moves, so a group whose ball keeps the margin is
passed over: a mesh of 20,000 vertices away from the primitive costs a few dozen distances.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]

SPHERE, BOX, CYLINDER, CAPSULE = 0, 1, 2, 3
"""The primitives :func:`any_vertex_within` measures to, centred in their frame (axis ``z``)."""
GROUPS_PER_AXIS = 4
"""The mesh's box is cut into this many cells along each axis; a cell's vertices are a group."""


def primitive_of(shape: Any) -> tuple[int, FloatArray] | None:
    """The kind and ``(3,)`` sizes [m] of a coal primitive, ``None`` for any other shape.

    Sizes: a sphere's radius; a box's half sides; a cylinder's or capsule's radius and half
    length.
    """
    if isinstance(shape, coal.Sphere):
        return SPHERE, np.array([shape.radius, 0.0, 0.0])
    if isinstance(shape, coal.Box):
        return BOX, np.asarray(shape.halfSide, dtype=float).copy()
    if isinstance(shape, coal.Cylinder):
        return CYLINDER, np.array([shape.radius, shape.halfLength, 0.0])
    if isinstance(shape, coal.Capsule):
        return CAPSULE, np.array([shape.radius, shape.halfLength, 0.0])
    return None


@dataclass(frozen=True)
class VertexGroups:
    """A mesh's distinct vertices, grouped by cell of its box, each group in a ball.

    Attributes:
        vertices: ``(V, 3)`` [m], each group's contiguous.
        starts: ``(G + 1,)`` group ``g`` is ``vertices[starts[g]:starts[g + 1]]``.
        centres: ``(G, 3)`` the balls' centres [m].
        radii: ``(G,)`` the balls' radii [m]: every vertex of its group within.
    """

    vertices: FloatArray
    starts: NDArray[np.int64]
    centres: FloatArray
    radii: FloatArray

    def within(self, placement: Any, primitive: tuple[int, FloatArray], margin_m: float) -> bool:
        """Whether a vertex lies closer than ``margin_m`` [m] to ``primitive`` (:func:`primitive_of`).

        ``placement``: the vertices' frame in the primitive's (a ``pinocchio.SE3``).
        """
        kind, sizes = primitive
        rotation, translation = placement.rotation, placement.translation
        groups = (self.vertices, self.starts, self.centres, self.radii)
        return bool(any_vertex_within(*groups, rotation, translation, kind, sizes, margin_m))


def vertex_groups(points: FloatArray) -> VertexGroups:
    """``points`` ``(V, 3)`` [m] (a mesh's corners) as :class:`VertexGroups`."""
    vertices = np.asarray(points, dtype=float).reshape(-1, 3)
    low, span = vertices.min(axis=0), np.ptp(vertices, axis=0)
    cells = np.minimum((vertices - low) / np.maximum(span, 1e-12) * GROUPS_PER_AXIS, GROUPS_PER_AXIS - 1)
    cell = cells.astype(np.int64) @ np.array([GROUPS_PER_AXIS**2, GROUPS_PER_AXIS, 1])
    order = np.argsort(cell, kind="stable")
    vertices, cell = np.ascontiguousarray(vertices[order]), cell[order]
    starts = np.flatnonzero(np.r_[True, cell[1:] != cell[:-1], True]).astype(np.int64)
    groups = [vertices[a:b] for a, b in itertools.pairwise(starts)]
    centres = np.array([group.mean(axis=0) for group in groups]).reshape(-1, 3)
    radii = np.array([np.linalg.norm(g - c, axis=1).max() for g, c in zip(groups, centres, strict=True)])
    return VertexGroups(vertices, starts, centres, radii.reshape(-1))


@njit_inline
def _distance(kind: int, sizes: FloatArray, px: float, py: float, pz: float) -> float:
    """The signed distance [m] from the point ``(px, py, pz)``, in the primitive's frame, to it."""
    if kind == SPHERE:
        return float(np.sqrt(px * px + py * py + pz * pz) - sizes[0])
    if kind == BOX:
        qx, qy, qz = abs(px) - sizes[0], abs(py) - sizes[1], abs(pz) - sizes[2]
        ox, oy, oz = max(qx, 0.0), max(qy, 0.0), max(qz, 0.0)
        return float(np.sqrt(ox * ox + oy * oy + oz * oz) + min(max(qx, max(qy, qz)), 0.0))
    if kind == CYLINDER:
        radial, axial = np.sqrt(px * px + py * py) - sizes[0], abs(pz) - sizes[1]
        outer_r, outer_a = max(radial, 0.0), max(axial, 0.0)
        return float(np.sqrt(outer_r * outer_r + outer_a * outer_a) + min(max(radial, axial), 0.0))
    off_axis = pz - min(max(pz, -sizes[1]), sizes[1])  # a capsule: to its axis' segment, less its radius
    return float(np.sqrt(px * px + py * py + off_axis * off_axis) - sizes[0])


@njit_inline
def _moved(rotation: FloatArray, translation: FloatArray, point: FloatArray) -> tuple[float, float, float]:
    """``point`` ``(3,)`` rotated, then translated."""
    r, (x, y, z) = rotation, (point[0], point[1], point[2])
    return (
        r[0, 0] * x + r[0, 1] * y + r[0, 2] * z + translation[0],
        r[1, 0] * x + r[1, 1] * y + r[1, 2] * z + translation[1],
        r[2, 0] * x + r[2, 1] * y + r[2, 2] * z + translation[2],
    )


@njit
def any_vertex_within(
    vertices: FloatArray,
    starts: NDArray[np.int64],
    centres: FloatArray,
    radii: FloatArray,
    rotation: FloatArray,
    translation: FloatArray,
    kind: int,
    sizes: FloatArray,
    margin_m: float,
) -> bool:
    """Whether a vertex of :class:`VertexGroups` lies closer than ``margin_m`` [m] to the primitive.

    ``rotation`` ``(3, 3)`` and ``translation`` ``(3,)`` [m] place the vertices' frame in the
    primitive's; ``kind`` and ``sizes`` are :func:`primitive_of`'s. A vertex inside counts (its
    signed distance is below zero). A group whose ball keeps the margin is passed over; the
    search stops at the first vertex close enough.
    """
    for g in range(starts.shape[0] - 1):
        px, py, pz = _moved(rotation, translation, centres[g])
        if _distance(kind, sizes, px, py, pz) - radii[g] >= margin_m:
            continue
        for v in range(starts[g], starts[g + 1]):
            px, py, pz = _moved(rotation, translation, vertices[v])
            if _distance(kind, sizes, px, py, pz) < margin_m:
                return True
    return False


class Mesh(Protocol):
    """A mesh as the witness reads it (:class:`cpr_kin.shapes.exact_meshes.ExactMesh` is one)."""

    @property
    def vertex_groups(self) -> VertexGroups:
        """Its distinct corners, in its frame, grouped."""
        ...


class VertexWitness:
    """Proofs that a geometry model's mesh and primitive geometries come within a margin.

    Args:
        shapes: the geometry model's shapes, by geometry index.
        meshes: the exact meshes, by the index of the geometry they refine.
    """

    def __init__(self, shapes: Sequence[Any], meshes: Mapping[int, Mesh]) -> None:
        self._shapes, self._meshes = shapes, meshes
        self._primitives: dict[int, tuple[int, FloatArray] | None] = {}

    def proves(self, a: int, at_a: Any, b: int, at_b: Any, margin_m: float) -> bool:
        """Whether a vertex of one's exact mesh lies within ``margin_m`` [m] of the other, a primitive.

        ``at_a``, ``at_b``: the placements (``pinocchio.SE3``) of ``a``'s mesh where it has one,
        else of its shape, and of ``b``'s. ``False`` where neither pairs a mesh with a
        primitive, or no vertex is that close: then nothing is proven.
        """
        for mesh_side, at_mesh, other, at_other in ((a, at_a, b, at_b), (b, at_b, a, at_a)):
            mesh = self._meshes.get(mesh_side)
            if mesh is None or other in self._meshes:
                continue
            if other not in self._primitives:
                self._primitives[other] = primitive_of(self._shapes[other])
            primitive = self._primitives[other]
            if primitive is None:
                continue
            return mesh.vertex_groups.within(at_other.actInv(at_mesh), primitive, margin_m)
        return False
