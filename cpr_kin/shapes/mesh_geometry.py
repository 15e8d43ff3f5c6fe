"""Meshes as coal shapes: whether points span a volume (Qhull's precondition), their hull and its planes.

And a mesh obstacle's geometry.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.errors import ObstacleError
from cpr_kin.common.names import shown
from cpr_kin.shapes.obstacle_ranges import MAX_COORDINATE_M, MAX_MESH_VERTICES

FLAT_SHARE = 1e-6
"""A point set thinner than this share of its size (its extent, or its distance from the origin
where that is larger) across its thinnest direction spans no volume. coal's Qhull crashed on
boxes 1.5e-8 of their extent thin, and built them from 5e-8 on: this leaves a margin."""


def spans_volume(points: Any) -> bool:
    """Whether ``points`` ``(N, 3)`` span a volume: Qhull can build their convex hull.

    A flat (or line-like) set has a hull of no volume, which SciPy's Qhull refuses and coal's
    crashes on (a segmentation fault, not an exception): ask this first. Thickness and size are
    root-mean-square distances (the thinnest and widest principal directions' and from the
    origin), so Qhull's precision, relative to the coordinates, is covered where the set lies
    far from its frame's origin.
    """
    vertices = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(vertices) < 4:
        return False
    spread = np.linalg.svd(vertices - vertices.mean(axis=0), compute_uv=False) / np.sqrt(len(vertices))
    size = max(float(spread[0]), float(np.sqrt(np.mean(np.sum(vertices**2, axis=1)))), 1e-300)
    return bool(spread[-1] > FLAT_SHARE * size)


def hull_planes(points: Any) -> NDArray[np.float64]:
    """``(H, 4)`` the facets' planes of the convex hull of ``points`` ``(..., 3)``, ``n . x + d <= 0`` inside.

    By coal's Qhull (options ``Qt``), which the robot's hulls are built with: SciPy's
    ``spatial`` (a tenth of a second to import) is not needed to load a robot. None for a
    flat set (:func:`spans_volume`): no point is then outside a plane, and the winding number
    alone decides.
    """
    if not spans_volume(points):
        return np.empty((0, 4))
    hull = convex_hull(points)
    return np.column_stack([np.asarray(hull.normals()), np.asarray(hull.offsets()).ravel()])


def convex_hull(points: Any) -> Any:
    """The convex hull (a ``coal.Convex``) of ``points`` ``(..., 3)`` [m]: coal's Qhull, options ``Qt``.

    As the robot's hulls are built. The points must span a volume (:func:`spans_volume`): coal
    crashes on a flat set.
    """
    import coal

    corners = coal.StdVec_Vec3s()
    corners.extend(list(np.asarray(points, dtype=float).reshape(-1, 3)))
    return coal.Convex.convexHull(corners, True, "Qt")


def mesh_geometry(path: Path, scale: float, convex: bool, name: str) -> Any:
    """The coal geometry of mesh obstacle ``name``: its convex hull (``convex``) or its triangles.

    ``path`` the mesh file, its vertices multiplied by ``scale``.

    Raises:
        ObstacleError: a file that is no mesh, has no triangles, too many vertices, vertices
            not finite or too far, or (``convex``) no volume to make a hull of.
    """
    import coal
    import trimesh  # only needed for mesh obstacles

    what = f"obstacle '{name}': mesh '{Path(str(path)).name}'"
    try:
        mesh: Any = trimesh.load(str(path), force="mesh")
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise ObstacleError(f"{what} cannot be read: {shown(str(exc))}") from None
    vertices = np.asarray(getattr(mesh, "vertices", np.empty((0, 3))), dtype=np.float64)
    faces = np.asarray(getattr(mesh, "faces", np.empty((0, 3))), dtype=np.int64)
    if len(faces) == 0:
        raise ObstacleError(f"{what} has no triangles")
    if len(vertices) > MAX_MESH_VERTICES:
        raise ObstacleError(f"{what} has {len(vertices)} vertices; at most {MAX_MESH_VERTICES}")
    if not np.all(np.isfinite(vertices)) or np.abs(vertices * scale).max() > MAX_COORDINATE_M:
        raise ObstacleError(f"{what} has vertices that are not finite or beyond {MAX_COORDINATE_M:g} m")
    if convex:
        if not spans_volume(vertices):
            raise ObstacleError(
                f"{what} is flat (its vertices span no volume), so it has no convex hull; "
                "give a solid mesh, or convex: false to use its surface"
            )
        try:
            hull = mesh.convex_hull
        except Exception as exc:  # Qhull's errors for degenerate input
            raise ObstacleError(f"{what} has no convex hull: {shown(str(exc))}") from None
        vertices, faces = (
            np.asarray(hull.vertices, dtype=np.float64),
            np.asarray(hull.faces, dtype=np.int64),
        )
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(faces), len(vertices))
    bvh.addVertices(vertices * scale)
    bvh.addTriangles(faces)
    bvh.endModel()
    if convex:
        bvh.buildConvexRepresentation(False)
        return bvh.convex
    return bvh
