"""Cheap lower bounds of robot-obstacle distances, for many configurations at once.

Each robot geometry is enclosed in a capsule (a segment grown by a radius) fixed to its
joint; each obstacle is bounded in its own frame by a shape whose distance to a segment is
a few lines of arithmetic. Compiled code places the capsules with the kinematic chain
(:mod:`cpr_kin.bounds.batch_kinematics`) and bounds every pair, several times faster than coal's
yes/no test (``docs/benchmarks.md``). A positive bound is at most coal's
distance (shapes that overlap get a bound <= 0), so a configuration whose bounds all exceed
a margin keeps it for certain: :meth:`cpr_kin.CollisionWorld.margin_violated` sends coal only
the pairs of the others whose bound does not (:meth:`PairBounds.pairs_below`). These tests
first compare each capsule with clusters of nearby obstacles (:mod:`cpr_kin.bounds.obstacle_blocks`),
then the bounding spheres of each capsule and obstacle (most pairs are far apart);
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
from cpr_kin.bounds.bound_kernels import groups_below, pair_bounds
from cpr_kin.bounds.capsule_fit import Capsule, fitted_capsule
from cpr_kin.bounds.obstacle_blocks import obstacle_blocks
from cpr_kin.bounds.obstacle_bounds import ObstacleArrays, local_box, obstacle_arrays, shape_vertices
from cpr_kin.shapes.coal_queries import swept_radius_m
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
    centre, half = local_box(geometry)
    axis = int(np.argmax(half))
    ends = np.array([centre, centre])
    ends[0, axis] -= half[axis]
    ends[1, axis] += half[axis]
    boxed = Capsule(ends, float(np.linalg.norm(np.delete(half, axis))))
    vertices = shape_vertices(geometry)
    if vertices is None:
        return boxed.ends, boxed.radius
    fitted = fitted_capsule(vertices)
    fitted = Capsule(fitted.ends, fitted.radius + swept_radius_m(geometry))
    best = min((boxed, fitted), key=lambda capsule: capsule.volume)
    return best.ends, best.radius


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


KnownCapsules = dict[int, tuple[int, FloatArray, float]]
"""Capsules computed before, by geometry index: joint (``-1``: the world), ends ``(2, 3)`` [m], radius [m]."""


def joint_capsules(
    collision_model: Any, geometries: Sequence[int], known: KnownCapsules | None = None
) -> JointCapsules:
    """The capsules (:func:`bounding_capsule`) of ``collision_model``'s ``geometries``, in joint frames.

    ``known``: those computed before for ``collision_model``, taken from it and the others
    added to it (a robot's, kept for every world it plans in: the capsule fits are its dearest part).
    """
    known = {} if known is None else known
    ends, radii, joints = [], [], []
    for g in geometries:
        if g not in known:
            obj = collision_model.geometryObjects[g]
            local, radius = bounding_capsule(obj.geometry)
            placement = obj.placement  # geometry in its joint's frame
            at = local @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
            known[g] = (int(obj.parentJoint) - 1, at, radius)  # joint -1: fixed to the world
        joint, at, radius = known[g]
        ends.append(at)
        radii.append(radius)
        joints.append(joint)
    capsule_ends = np.array(ends, dtype=float).reshape(-1, 2, 3)
    capsule_radius = np.array(radii, dtype=float)
    reach = np.linalg.norm(capsule_ends[:, 1] - capsule_ends[:, 0], axis=1) / 2 + capsule_radius
    return JointCapsules(np.array(joints, dtype=np.int64), capsule_ends, capsule_radius, reach)


class PairBounds:
    """Lower bounds of robot-obstacle pair distances, for batches of configurations.

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: the robot's Pinocchio geometry model.
        obstacles: the obstacles.
        pairs: ``(robot geometry index, obstacle index)`` per output column.
        chain: ``model``'s kinematic chain, where the caller keeps it (default: built).
        known: the capsules of ``collision_model`` computed before (:func:`joint_capsules`).
        shapes: the obstacles' bounds (:func:`~cpr_kin.bounds.obstacle_bounds.obstacle_arrays`),
            where the caller keeps them for every set of pairs among them (default: built).
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        obstacles: Sequence[Obstacle],
        pairs: Sequence[tuple[int, int]],
        *,
        chain: KinematicChain | None = None,
        known: KnownCapsules | None = None,
        shapes: ObstacleArrays | None = None,
    ) -> None:
        self._chain = KinematicChain.from_model(model) if chain is None else chain
        geometries = sorted({g for g, _ in pairs})
        slot = {g: k for k, g in enumerate(geometries)}
        capsules = joint_capsules(collision_model, geometries, known)
        self._capsules = (capsules.joint, capsules.ends, capsules.radius)
        self._pairs = (
            np.array([slot[g] for g, _ in pairs], dtype=np.int64),
            np.array([k for _, k in pairs], dtype=np.int64),
        )
        shapes = obstacle_arrays(obstacles) if shapes is None else shapes
        self._pair_columns = np.arange(len(pairs), dtype=np.int64)  # each pair its own group
        self._obstacles = (shapes.kind, shapes.rotation, shapes.centre, shapes.radius, shapes.half)
        obstacle_reach, obstacle_extent = shapes.reach, shapes.extent
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
            obstacle_blocks(*self._pairs, shapes.centre, obstacle_extent).arrays,
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
