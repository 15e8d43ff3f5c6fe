"""The shape that bounds each obstacle in the compiled pair bounds, and the shape helpers they share.

:class:`~cpr_kin.bounds.pair_bounds.PairBounds` bounds a robot capsule's distance to an obstacle
by the obstacle's own shape where the kernels know it (sphere, cylinder, capsule, box) and by
a box or a fitted capsule about any other (:func:`obstacle_bound`); the same helpers give a
robot geometry's box and vertices (:func:`~cpr_kin.bounds.pair_bounds.bounding_capsule`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.bound_kernels import BOX, CAPSULE, CYLINDER, SPHERE
from cpr_kin.bounds.capsule_fit import Capsule, fitted_capsule, frame_about
from cpr_kin.shapes.obstacles import Obstacle

FloatArray = NDArray[np.float64]


def local_box(geometry: Any) -> tuple[FloatArray, FloatArray]:
    """Centre and half sides [m] of a coal geometry's bounding box in its own frame."""
    geometry.computeLocalAABB()
    low = np.asarray(geometry.aabb_local.min_, dtype=float)
    high = np.asarray(geometry.aabb_local.max_, dtype=float)
    return (low + high) / 2, (high - low) / 2


def shape_vertices(geometry: Any) -> FloatArray | None:
    """``(N, 3)`` a mesh's vertices in its own frame [m]; ``None`` for another shape or an empty mesh."""
    if isinstance(geometry, coal.ConvexBase):
        points = np.asarray(geometry.points(), dtype=float)
    elif isinstance(geometry, coal.BVHModelBase):
        points = np.asarray(geometry.vertices(), dtype=float)
    else:
        return None
    return points.reshape(-1, 3) if points.size else None


class ObstacleBound(NamedTuple):
    """The shape that bounds an obstacle in the compiled kernels, in the world.

    Attributes:
        kind: :data:`~cpr_kin.bounds.bound_kernels.SPHERE`, ``CYLINDER``, ``CAPSULE`` or ``BOX``.
        rotation: ``(3, 3)`` its axes in the world's (a cylinder's or capsule's along z).
        centre: ``(3,)`` its centre [m].
        radius: a sphere's, cylinder's or capsule's radius [m] (0 for a box).
        half: ``(3,)`` a box's half sides; a cylinder's or capsule's half length as z [m].
        reach: the radius of its bounding sphere about the centre [m] (a box's half diagonal).
    """

    kind: int
    rotation: FloatArray
    centre: FloatArray
    radius: float
    half: FloatArray
    reach: float

    @property
    def world_extent(self) -> FloatArray:
        """``(3,)`` half sides [m] of a box in the world's axes about the centre that holds the shape.

        Its own box (a box's half sides; a cylinder's ``(R, R, h)``, a capsule's ``(R, R, h + R)``,
        a sphere's radius on every axis) turned into the world's axes: the margin test's first
        test (:func:`~cpr_kin.bounds.bound_kernels.groups_below`).
        """
        if self.kind == SPHERE:
            return np.full(3, self.radius)
        own = self.half
        if self.kind != BOX:
            own = np.array(
                [self.radius, self.radius, self.half[2] + (self.radius if self.kind == CAPSULE else 0.0)]
            )
        extent: FloatArray = np.abs(self.rotation) @ own
        return extent


class ObstacleArrays(NamedTuple):
    """The obstacles' bounds (:func:`obstacle_bound`) as the compiled kernels take them, one row each.

    Attributes:
        kind: ``(O,)`` each bound's kind.
        rotation: ``(O, 3, 3)`` its axes in the world's.
        centre: ``(O, 3)`` its centre [m].
        radius: ``(O,)`` its radius [m].
        half: ``(O, 3)`` its half sides or half length [m].
        reach: ``(O,)`` its bounding sphere's radius [m].
        extent: ``(O, 3)`` the half sides of its box in the world's axes [m]
            (:attr:`ObstacleBound.world_extent`).
    """

    kind: NDArray[np.int64]
    rotation: FloatArray
    centre: FloatArray
    radius: FloatArray
    half: FloatArray
    reach: FloatArray
    extent: FloatArray


def obstacle_arrays(obstacles: Sequence[Obstacle]) -> ObstacleArrays:
    """:class:`ObstacleArrays` of ``obstacles``: every pair set among them shares them."""
    bounds = [obstacle_bound(obstacle) for obstacle in obstacles]
    return ObstacleArrays(
        np.array([b.kind for b in bounds], dtype=np.int64),
        np.array([b.rotation for b in bounds], dtype=float).reshape(-1, 3, 3),
        np.array([b.centre for b in bounds], dtype=float).reshape(-1, 3),
        np.array([b.radius for b in bounds], dtype=float),
        np.array([b.half for b in bounds], dtype=float).reshape(-1, 3),
        np.array([b.reach for b in bounds], dtype=float),
        np.array([b.world_extent for b in bounds], dtype=float).reshape(-1, 3),
    )


def obstacle_bound(obstacle: Obstacle) -> ObstacleBound:
    """The shape that bounds ``obstacle`` in the compiled kernels.

    A sphere, cylinder, capsule or box bounds itself. A mesh is bounded by its
    bounding box or by the capsule fitted to its vertices
    (:func:`cpr_kin.bounds.capsule_fit.fitted_capsule`), whichever is smaller.
    """
    placement = obstacle.placement
    rotation = np.asarray(placement.rotation, dtype=float)
    origin = np.asarray(placement.translation, dtype=float)
    radius = float(obstacle.radius or 0.0)
    if obstacle.shape == "sphere":
        return ObstacleBound(SPHERE, rotation, origin, radius, np.zeros(3), radius)
    if obstacle.shape in ("cylinder", "capsule"):
        half_length = float(obstacle.length or 0.0) / 2
        half = np.array([0.0, 0.0, half_length])
        if obstacle.shape == "cylinder":
            return ObstacleBound(
                CYLINDER, rotation, origin, radius, half, float(np.hypot(radius, half_length))
            )
        return ObstacleBound(CAPSULE, rotation, origin, radius, half, radius + half_length)
    geometry = obstacle.geometry()
    centre, half = local_box(geometry)  # a box, or a mesh's bounding box
    diagonal = float(np.linalg.norm(half))
    vertices = shape_vertices(geometry)
    if vertices is not None:  # a mesh: the capsule fitted to it where that is smaller than its box
        fitted = fitted_capsule(vertices)
        if fitted.volume < 8.0 * float(np.prod(half)):
            return _capsule_bound(fitted, rotation, origin)
    return ObstacleBound(BOX, rotation, origin + rotation @ centre, 0.0, half, diagonal)


def _capsule_bound(capsule: Capsule, rotation: FloatArray, origin: FloatArray) -> ObstacleBound:
    """The :class:`ObstacleBound` of a capsule given in the obstacle's frame (its axis as z)."""
    middle = capsule.ends.mean(axis=0)
    along = capsule.ends[1] - capsule.ends[0]
    half_length = float(np.linalg.norm(along)) / 2
    axes = frame_about(along if half_length > 0.0 else np.array([0.0, 0.0, 1.0]))  # in the obstacle's frame
    half = np.array([0.0, 0.0, half_length])
    reach = capsule.radius + half_length
    return ObstacleBound(CAPSULE, rotation @ axes, origin + rotation @ middle, capsule.radius, half, reach)
