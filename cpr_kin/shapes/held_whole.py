"""Whether one shape may lie wholly inside a link's exact mesh, their surfaces apart.

Where two hulls penetrate, their meshes may still be apart, unless one holds the other whole:
coal's distance of two surfaces does not see a shape inside a closed mesh. A point of the inner
shape (one in each of its pieces) inside the outer mesh, by winding number
(:meth:`cpr_kin.shapes.exact_meshes.ExactMesh.holds_any`), tells
(:mod:`cpr_kin.shapes.exact_pairs`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import coal
import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from cpr_kin.shapes.exact_meshes import ExactMesh

FloatArray = NDArray[np.float64]


def may_hold(outer: ExactMesh | None, points: FloatArray | None, at_outer: Any, at_inner: Any) -> bool:
    """Whether the mesh ``outer`` may hold whole the shape whose :func:`inner_points` are ``points``.

    ``at_outer`` and ``at_inner`` (``pinocchio.SE3``) place the mesh and the shape in the world.
    ``False`` where there is no outer mesh; ``True`` where the inner shape's pieces are not known.
    """
    if outer is None:
        return False
    if points is None:
        return True  # voxels, loose triangles, a mesh of many pieces: cannot be told
    if not len(points):
        return False
    inner_in_outer = at_outer.actInv(at_inner)
    return outer.holds_any(points, inner_in_outer.rotation, inner_in_outer.translation)


def inner_points(shape: Any, mesh: ExactMesh | None) -> FloatArray | None:
    """Points of a shape in its frame, one in each piece: inside an outer mesh if the shape is held whole.

    An exact mesh's piece points; one point of a bounded primitive or convex shape; none of a
    half-space or a plane (no bounded mesh holds one); ``None`` where the pieces are not known.
    """
    if mesh is not None:
        return mesh.piece_points
    if isinstance(shape, coal.ConvexBase):
        return np.asarray([shape.point(0)], dtype=float)
    if isinstance(shape, (coal.Halfspace, coal.Plane)):
        return np.zeros((0, 3))
    if isinstance(shape, coal.TriangleP):
        return np.asarray([shape.a], dtype=float)
    if isinstance(shape, coal.ShapeBase):
        return np.zeros((1, 3))  # a box, sphere, cylinder, capsule, cone or ellipsoid: centred on its origin
    return None
