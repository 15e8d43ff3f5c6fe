"""A geometry model's shapes as arrays, as the compiled GJK (:mod:`cpr_kin.shapes.convex_gjk`) reads them."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.shapes.coal_queries import swept_radius_m
from cpr_kin.shapes.convex_gjk import BOX, CAPSULE, CONVEX, CYLINDER, SPHERE, UNSUPPORTED, Cores

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

MAX_VERTICES = 512
"""A convex shape with more vertices is left to coal, whose support walks the hull's edges where
the compiled test visits every vertex (a hull of thousands of vertices, a gripper's flange, costs
it more than coal's call)."""


@dataclass(frozen=True)
class GeometryShapes:
    """A geometry model's shapes as :func:`~cpr_kin.shapes.convex_gjk.support` takes them.

    Attributes:
        kinds: ``(G,)`` each geometry's kind (``UNSUPPORTED``: coal decides its pairs; a mesh, a plane,
            a convex shape of more than :data:`MAX_VERTICES` vertices).
        half: ``(G, 3)`` a box's half sides [m]; a capsule's or cylinder's radius and half length.
        first: ``(G + 1,)`` where each convex geometry's vertices begin in ``vertices``.
        vertices: ``(V, 3)`` the convex geometries' vertices in their own frames [m].
        radii: ``(G,)`` the radius sweeping each core (a sphere's, a capsule's, coal's swept
            sphere radius) [m].
        joints: ``(G,)`` the joint each geometry is fixed to (its index in the kinematic chain;
            -1: the world).
        rotations: ``(G, 3, 3)`` its placement in that joint's frame.
        translations: ``(G, 3)`` [m].
    """

    kinds: IntArray
    half: FloatArray
    first: IntArray
    vertices: FloatArray
    radii: FloatArray
    joints: IntArray
    rotations: FloatArray
    translations: FloatArray

    @property
    def cores(self) -> Cores:
        """The cores as :func:`~cpr_kin.shapes.convex_gjk.support` reads them."""
        return self.kinds, self.half, self.first, self.vertices

    @classmethod
    def of(cls, geometry_model: Any) -> GeometryShapes:
        """The shapes of a Pinocchio geometry model's geometries."""
        objects = list(geometry_model.geometryObjects)
        kinds = np.full(len(objects), UNSUPPORTED, dtype=np.int64)
        half, radii = np.zeros((len(objects), 3)), np.zeros(len(objects))
        counts, vertices = np.zeros(len(objects), dtype=np.int64), []
        for g, obj in enumerate(objects):
            shape = obj.geometry
            radii[g] = swept = swept_radius_m(shape)
            if isinstance(shape, coal.ConvexBase) and shape.num_points <= MAX_VERTICES:
                points = np.asarray(shape.points(), dtype=float).reshape(-1, 3)
                kinds[g], counts[g] = CONVEX, len(points)
                vertices.append(points)
            elif isinstance(shape, coal.Box):
                kinds[g], half[g] = BOX, np.asarray(shape.halfSide, dtype=float)
            elif isinstance(shape, coal.Sphere):
                kinds[g], radii[g] = SPHERE, swept + float(shape.radius)
            elif isinstance(shape, coal.Capsule):
                kinds[g], half[g, 1], radii[g] = CAPSULE, float(shape.halfLength), swept + float(shape.radius)
            elif isinstance(shape, coal.Cylinder):
                kinds[g], half[g, :2] = CYLINDER, (float(shape.radius), float(shape.halfLength))
        return cls(
            kinds=kinds,
            half=half,
            first=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
            vertices=np.concatenate(vertices) if vertices else np.zeros((0, 3)),
            radii=radii,
            joints=np.array([obj.parentJoint - 1 for obj in objects], dtype=np.int64),
            rotations=np.array([obj.placement.rotation for obj in objects], dtype=float).reshape(-1, 3, 3),
            translations=np.array([obj.placement.translation for obj in objects], dtype=float).reshape(-1, 3),
        )
