"""Cheap lower bounds of robot-obstacle distances, for many configurations at once.

Each robot geometry is enclosed in a capsule (a segment grown by a radius) fixed to its
joint; each obstacle is bounded in its own frame by a shape whose distance to a segment is
a few lines of arithmetic. Compiled code places the capsules with the kinematic chain
(:mod:`cpr_kin.bounds.batch_kinematics`) and bounds every pair, several times faster than coal's
yes/no test (``docs/benchmarks.md``). A positive bound is at most coal's
distance (shapes that overlap get a bound <= 0), so a configuration whose bounds all exceed
a margin keeps it for certain: :meth:`cpr_kin.CollisionWorld.margin_violated` sends coal only
the pairs of the others whose bound does not (:meth:`PairBounds.pairs_below`). These tests
first compare the bounding spheres of each capsule and obstacle (most pairs are far apart);
:meth:`PairBounds.any_below` stops at a configuration's first uncertain pair.
The bounds themselves are compiled (:mod:`cpr_kin.bounds.bound_kernels`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import coal
import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import KinematicChain
from cpr_kin.bounds.bound_kernels import BOX, CAPSULE, CYLINDER, SPHERE, groups_below, pair_bounds
from cpr_kin.bounds.capsule_fit import Capsule, fitted_capsule, frame_about
from cpr_kin.shapes.obstacles import Obstacle

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


def bounding_capsule(geometry: Any) -> tuple[FloatArray, float]:
    """A capsule containing a coal geometry: segment end points ``(2, 3)`` [m] and radius [m].

    In the geometry's own frame. Spheres, capsules and cylinders keep their axis and radius
    (the capsule's caps cover a cylinder's rims). A mesh (a convex one or a triangle soup)
    gets the capsule fitted to its vertices (:func:`cpr_kin.bounds.capsule_fit.fitted_capsule`)
    or its bounding box's, whichever is smaller; any other shape its bounding box's: the
    box's longest axis, with the box's half diagonal across that axis as radius. A swept
    sphere radius grows the capsule by as much.
    """
    if isinstance(geometry, coal.Sphere):
        return np.zeros((2, 3)), float(geometry.radius)
    if isinstance(geometry, coal.Capsule | coal.Cylinder):
        half_length = float(geometry.halfLength)
        return np.array([[0.0, 0.0, -half_length], [0.0, 0.0, half_length]]), float(geometry.radius)
    centre, half = _local_box(geometry)
    axis = int(np.argmax(half))
    ends = np.array([centre, centre])
    ends[0, axis] -= half[axis]
    ends[1, axis] += half[axis]
    boxed = Capsule(ends, float(np.linalg.norm(np.delete(half, axis))))
    vertices = _vertices(geometry)
    if vertices is None:
        return boxed.ends, boxed.radius
    fitted = fitted_capsule(vertices)
    swept = float(geometry.getSweptSphereRadius()) if hasattr(geometry, "getSweptSphereRadius") else 0.0
    fitted = Capsule(fitted.ends, fitted.radius + swept)
    best = min((boxed, fitted), key=lambda capsule: capsule.volume)
    return best.ends, best.radius


def _vertices(geometry: Any) -> FloatArray | None:
    """``(N, 3)`` a mesh's vertices in its own frame [m]; ``None`` for another shape or an empty mesh."""
    if isinstance(geometry, coal.ConvexBase):
        points = np.asarray(geometry.points(), dtype=float)
    elif isinstance(geometry, coal.BVHModelBase):
        points = np.asarray(geometry.vertices(), dtype=float)
    else:
        return None
    return points.reshape(-1, 3) if points.size else None


class JointCapsules(NamedTuple):
    """Capsules enclosing geometries, each fixed to its joint (the compiled kernels' arguments).

    Attributes:
        joint: ``(G,)`` the joint each moves with, ``-1``: fixed to the world.
        ends: ``(G, 2, 3)`` its segment's end points in that joint's frame [m].
        radius: ``(G,)`` its radius [m].
        reach: ``(G,)`` the radius of its bounding sphere about the segment's middle [m].
    """

    joint: IntArray
    ends: FloatArray
    radius: FloatArray
    reach: FloatArray


def joint_capsules(collision_model: Any, geometries: Sequence[int]) -> JointCapsules:
    """The capsules (:func:`bounding_capsule`) of ``collision_model``'s ``geometries``, in joint frames."""
    ends, radii, joints = [], [], []
    for g in geometries:
        obj = collision_model.geometryObjects[g]
        local, radius = bounding_capsule(obj.geometry)
        placement = obj.placement  # geometry in its joint's frame
        ends.append(local @ np.asarray(placement.rotation).T + np.asarray(placement.translation))
        radii.append(radius)
        joints.append(int(obj.parentJoint) - 1)  # -1: fixed to the world
    capsule_ends = np.array(ends, dtype=float).reshape(-1, 2, 3)
    capsule_radius = np.array(radii, dtype=float)
    reach = np.linalg.norm(capsule_ends[:, 1] - capsule_ends[:, 0], axis=1) / 2 + capsule_radius
    return JointCapsules(np.array(joints, dtype=np.int64), capsule_ends, capsule_radius, reach)


def _local_box(geometry: Any) -> tuple[FloatArray, FloatArray]:
    """Centre and half sides [m] of a coal geometry's bounding box in its own frame."""
    geometry.computeLocalAABB()
    low = np.asarray(geometry.aabb_local.min_, dtype=float)
    high = np.asarray(geometry.aabb_local.max_, dtype=float)
    return (low + high) / 2, (high - low) / 2


class PairBounds:
    """Lower bounds of robot-obstacle pair distances, for batches of configurations.

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: the robot's Pinocchio geometry model.
        obstacles: the obstacles.
        pairs: ``(robot geometry index, obstacle index)`` per output column.
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        obstacles: Sequence[Obstacle],
        pairs: Sequence[tuple[int, int]],
    ) -> None:
        self._chain = KinematicChain.from_model(model)
        geometries = sorted({g for g, _ in pairs})
        slot = {g: k for k, g in enumerate(geometries)}
        capsules = joint_capsules(collision_model, geometries)
        self._capsules = (capsules.joint, capsules.ends, capsules.radius)
        self._pairs = (
            np.array([slot[g] for g, _ in pairs], dtype=np.int64),
            np.array([k for _, k in pairs], dtype=np.int64),
        )
        bounds = [_obstacle_bound(obstacle) for obstacle in obstacles]
        self._pair_columns = np.arange(len(pairs), dtype=np.int64)  # each pair its own group
        self._obstacles = (
            np.array([b.kind for b in bounds], dtype=np.int64),
            np.array([b.rotation for b in bounds], dtype=float).reshape(-1, 3, 3),
            np.array([b.centre for b in bounds], dtype=float).reshape(-1, 3),
            np.array([b.radius for b in bounds], dtype=float),
            np.array([b.half for b in bounds], dtype=float).reshape(-1, 3),
        )
        obstacle_reach = np.array([b.reach for b in bounds], dtype=float)
        obstacle_extent = np.array([b.world_extent for b in bounds], dtype=float).reshape(-1, 3)
        # the compiled kernels' arguments after the configurations (and threshold) and the output
        self._arguments: tuple[Any, ...] = (
            self._chain.arrays,
            *self._capsules,
            *self._pairs,
            *self._obstacles,
        )
        self._any_arguments: tuple[Any, ...] = (
            self._chain.arrays,
            *self._capsules,
            capsules.reach,
            *self._pairs,
            *self._obstacles,
            obstacle_reach,
            obstacle_extent,
        )

    @property
    def n_pairs(self) -> int:
        """Number of pairs (output columns)."""
        return len(self._pairs[0])

    def __call__(self, q: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of each pair's distance at configurations ``q`` ``(N, nq)``."""
        batch = np.ascontiguousarray(q, dtype=float)
        out = np.empty((len(batch), self.n_pairs))
        pair_bounds(batch, out, *self._arguments)
        return out

    def any_below(self, q: FloatArray, threshold_m: float) -> BoolArray:
        """``(N,)`` whether some pair may be within ``threshold_m`` [m] at configurations ``q``.

        False only where every pair is certainly farther: by its bound of :meth:`__call__`
        or by the bounding spheres of the robot capsule and the obstacle, whichever is
        tested first. So it is at most ``(self(q) <= threshold_m).any(axis=1)``, and faster:
        far pairs cost only the spheres' test, and a configuration stops at its first
        uncertain pair.
        """
        return self._below(q, threshold_m, np.zeros(self.n_pairs, dtype=np.int64), 1)[:, 0]

    def pairs_below(self, q: FloatArray, threshold_m: float) -> BoolArray:
        """``(N, P)`` whether each pair may be within ``threshold_m`` [m] at configurations ``q``.

        :meth:`any_below` pair by pair: false where the pair's bounding spheres or its bound
        of :meth:`__call__` put it farther, what coal need not test
        (:mod:`cpr_kin.collision.obstacle_tests`).
        """
        return self._below(q, threshold_m, self._pair_columns, self.n_pairs)

    def _below(self, q: FloatArray, threshold_m: float, pair_group: IntArray, groups: int) -> BoolArray:
        batch = np.ascontiguousarray(q, dtype=float)
        out = np.empty((len(batch), groups), dtype=np.bool_)
        groups_below(batch, float(threshold_m), out, pair_group, *self._any_arguments)
        return out


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


def _obstacle_bound(obstacle: Obstacle) -> ObstacleBound:
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
    centre, half = _local_box(geometry)  # a box, or a mesh's bounding box
    diagonal = float(np.linalg.norm(half))
    vertices = _vertices(geometry)
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
