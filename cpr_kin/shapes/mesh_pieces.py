"""A concave mesh's triangles in a few convex pieces whose union holds every one of them.

Where a concave link's hull comes within a margin of another shape, its mesh decides
(:mod:`cpr_kin.shapes.exact_pairs`), and coal's test of a mesh of thousands of triangles costs
a hundred times a convex shape's: most of it where the hull is near or inside the other shape
and the mesh is clear, its bounding volumes overlapping the other shape down to many
triangles. Between the hull and the mesh, a few convex pieces decide most of those cases at
the cost of a few convex queries: every triangle lies in the convex hull of its piece, so where
every piece keeps a margin from a shape, every triangle does, and the mesh's test would say
clear. Where a piece comes within the margin, the mesh decides as before: the pieces only
spare the mesh's test, they never change an answer.

The pieces are made by cutting the triangles in two, and each side again (:data:`CUTS` times
down each branch): a triangle goes to the side of a plane its centre lies on, and the plane is
the one, among cuts across the corners' principal axes and the mesh frame's axes at a few
shares of the triangles (:data:`CUT_SHARES`), whose two sides' hulls have the least volume
together (estimated on :data:`VOLUME_SAMPLE` of the triangles, seeded): an L-shaped link falls
into its two arms. The pieces depend on the triangles alone and are kept on disk
(:mod:`cpr_kin.common.disk_cache`): a new process reads them.
"""

from __future__ import annotations

import hashlib
import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.disk_cache import cached_array
from cpr_kin.shapes.coal_queries import COLLIDE_MARGIN_AT_LEAST_M, as_transform
from cpr_kin.shapes.mesh_geometry import convex_hull, spans_volume

FloatArray = NDArray[np.float64]

CUTS = 2
"""Cuts down each branch: ``2 ** CUTS`` pieces, fewer where a side would span no volume."""
CUT_SHARES = (0.3, 0.5, 0.7)
"""Where a piece may be cut along an axis: these shares of its triangles' centres below the plane."""
VOLUME_SAMPLE = 256
"""Triangles of a piece whose corners estimate its sides' hull volumes when a cut is chosen."""
PIECES_VERSION = b"mesh-pieces-1"
"""Named in the disk cache's digest: a change to the cuts makes the pieces anew."""


def mesh_pieces(triangles: FloatArray) -> tuple[FloatArray, ...]:
    """The corners ``(V_k, 3)`` [m] of each convex piece of ``triangles`` ``(F, 3, 3)`` (module docstring).

    Every triangle's corners are those of one piece, so its piece's convex hull holds it. Empty
    where the triangles span no volume (no hull to hold them).
    """
    triangles = np.ascontiguousarray(triangles, dtype=float)
    digest = hashlib.sha256(triangles.tobytes() + PIECES_VERSION).hexdigest()

    def compute() -> FloatArray:
        if not spans_volume(triangles):
            return np.empty((0, 4))
        corners = [_corners(piece) for piece in _cut(triangles, CUTS, np.random.default_rng(0))]
        return np.concatenate(
            [np.column_stack([points, np.full(len(points), k)]) for k, points in enumerate(corners)]
        )

    labelled = cached_array("mesh-pieces", digest, compute)
    labels = labelled[:, 3].astype(np.int64)
    return tuple(labelled[labels == k, :3] for k in np.unique(labels))


def convex_pieces(triangles: FloatArray) -> tuple[coal.ConvexBase, ...]:
    """The convex hulls (coal's) of :func:`mesh_pieces`, in the triangles' frame."""
    return tuple(convex_hull(corners) for corners in mesh_pieces(triangles))


def pieces_apart(
    first: Sequence[Any], at_first: Any, second: Sequence[Any], at_second: Any, margin_m: float
) -> float | None:
    """The least distance [m] between ``first``'s and ``second``'s convex shapes, where it keeps ``margin_m``.

    Each side's shapes (a mesh's pieces, or one shape) placed at its ``coal.Transform3s``. The
    distance counts only where every pair of shapes is farther than ``margin_m`` by coal's
    error (:data:`~cpr_kin.shapes.coal_queries.COLLIDE_MARGIN_AT_LEAST_M`); ``None`` at the
    first pair that is not, or where a side has no shape (nothing proven).
    """
    if not (first and second):
        return None
    request, least = coal.DistanceRequest(), math.inf
    for shape_a in first:
        for shape_b in second:
            found = coal.distance(shape_a, at_first, shape_b, at_second, request, coal.DistanceResult())
            if found < margin_m + COLLIDE_MARGIN_AT_LEAST_M:
                return None
            least = min(least, found)
    return least


class Side(NamedTuple):
    """One side of a pair: its convex pieces, placed, and one convex shape that holds them, placed.

    Attributes:
        pieces: a mesh's pieces, or the side's one shape.
        at: the pieces' placement (a ``coal.Transform3s``).
        bound: a convex shape holding the pieces (a mesh's hull or capsule; the shape itself).
        bound_at: its placement (a ``pinocchio.SE3``, turned into coal's only where it is asked).
    """

    pieces: Sequence[Any]
    at: Any
    bound: Any
    bound_at: Any


def sides_apart(first: Side, second: Side, margin_m: float) -> float | None:
    """:func:`pieces_apart` of two sides; of two meshes, each one's pieces against the other's bound first.

    A bound holds its side's pieces, so where one side's pieces keep the margin from the other's
    bound they keep it from its pieces: four queries (or eight) where the pieces against each
    other ask sixteen, which stay the last resort.
    """
    if len(first.pieces) > 1 and len(second.pieces) > 1:
        for one, other in ((first, second), (second, first)):
            found = pieces_apart(one.pieces, one.at, (other.bound,), as_transform(other.bound_at), margin_m)
            if found is not None:
                return found
    return pieces_apart(first.pieces, first.at, second.pieces, second.at, margin_m)


def _cut(triangles: FloatArray, cuts: int, rng: np.random.Generator) -> list[FloatArray]:
    """``triangles`` in pieces, cut ``cuts`` times down each branch (fewer where no cut spans volumes)."""
    if cuts == 0:
        return [triangles]
    halves = _best_cut(triangles, rng)
    if halves is None:
        return [triangles]
    return _cut(halves[0], cuts - 1, rng) + _cut(halves[1], cuts - 1, rng)


def _best_cut(triangles: FloatArray, rng: np.random.Generator) -> tuple[FloatArray, FloatArray] | None:
    """The two sides of the plane whose hulls hold the least volume (``None``: no cut spans two volumes)."""
    centres = triangles.mean(axis=1)
    sample = np.sort(rng.permutation(len(triangles))[:VOLUME_SAMPLE])
    corners = triangles[sample].reshape(-1, 3)
    principal = np.linalg.svd(corners - corners.mean(axis=0), full_matrices=False)[2]
    ranked: list[tuple[float, NDArray[np.bool_]]] = []
    for axis in (*principal, *np.eye(3)):
        along = centres @ axis
        for share in CUT_SHARES:
            below = along <= np.quantile(along, share)
            estimated = (triangles[sample[below[sample]]], triangles[sample[~below[sample]]])
            if all(spans_volume(side) for side in estimated):
                volume = sum(convex_hull(_corners(side)).computeVolume() for side in estimated)
                ranked.append((volume, below))
    for _, below in sorted(ranked, key=lambda cut: cut[0]):
        sides = (triangles[below], triangles[~below])
        if all(spans_volume(side) for side in sides):
            return sides
    return None


def _corners(triangles: FloatArray) -> FloatArray:
    """The triangles' corners ``(V, 3)``, each once."""
    return np.unique(triangles.reshape(-1, 3), axis=0)
