"""Conservative bounds on where each robot geometry can be, over all configurations.

Each collision geometry is bounded by the convex hull of a few points plus a ball (its
bounding box's centre and radius, and separately its bounding box's corners), carried up
the kinematic tree: a prismatic joint sweeps the points over its travel; a revolute joint
(whose angle is free) folds them onto its axis and adds their largest distance from the axis
to the ball. Along the way, the largest distance of the set from each revolute axis bounds
how fast the geometry moves when that joint turns (:func:`cpr_kin.motion_radii`). At the
root the set is a segment on the first joint's axis plus a ball: a capsule that contains the
geometry in every configuration. A pair's distance changes only by the joints that carry one
of its geometries and not the other (:func:`relative_radii`). These bounds of a robot, kept
once per robot, and of its geometries against obstacles: :mod:`cpr_kin.collision.robot_reach`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Hull:
    """The convex hull of ``points`` ``(K, 3)`` grown by ``ball`` [m] (world frame)."""

    points: FloatArray
    ball: float

    def capsule(self) -> tuple[FloatArray, FloatArray, float, float]:
        """A capsule containing the hull.

        Returns its centre [m], unit axis, half length [m] and radius [m]: the segment
        spanning the points' bounding box diagonal, grown by the ball and by the points'
        largest distance from that line (zero when the points lie on one axis, as they do
        below a revolute root joint).
        """
        low, high = self.points.min(axis=0), self.points.max(axis=0)
        centre = (low + high) / 2
        half = float(np.linalg.norm(high - low)) / 2
        axis = (high - low) / (2 * half) if half > 0 else np.array([0.0, 0.0, 1.0])
        off_axis = float(_distance_from_axis(self.points - centre, axis).max())
        return centre, axis, half, self.ball + off_axis


@dataclass(frozen=True)
class GeometryReach:
    """Bounds for one collision geometry.

    Attributes:
        radii: per joint, the largest distance of the geometry from that joint's axis
            (revolute) or 1 (prismatic), 0 for joints that do not carry it [m or m/m].
        hulls: grown hulls each containing the geometry in every configuration, carried up
            from its bounding box's centre and radius, and from its bounding box's corners
            (which is tighter depends on the shape and the joints: use both).
    """

    radii: FloatArray
    hulls: tuple[Hull, ...]


def joint_axis(joint: Any) -> tuple[bool, FloatArray]:
    """(is prismatic, unit axis in the joint frame) of a one-degree-of-freedom joint."""
    jdata = joint.createData()
    joint.calc(jdata, np.zeros(joint.nq))
    subspace = np.asarray(jdata.S).ravel()
    linear, angular = subspace[:3], subspace[3:]
    prismatic = bool(np.linalg.norm(linear) > np.linalg.norm(angular))
    axis = linear if prismatic else angular
    return prismatic, axis / np.linalg.norm(axis)


def _distance_from_axis(points: FloatArray, axis: FloatArray) -> FloatArray:
    """Distances [m] of ``points`` ``(K, 3)`` from the line through the origin along ``axis``."""
    along = points @ axis
    return np.asarray(np.linalg.norm(points - np.outer(along, axis), axis=1))


def geometry_reach(
    model: Any, collision_model: Any, lower: FloatArray, upper: FloatArray
) -> list[GeometryReach]:
    """The bounds of every collision geometry of a Pinocchio model (one-DOF joints)."""
    axes = [joint_axis(model.joints[k]) for k in range(1, model.njoints)]
    bounds = []
    for obj in collision_model.geometryObjects:
        shape = obj.geometry
        shape.computeLocalAABB()
        box = shape.aabb_local
        low, high = np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)
        corners = np.array([[(low, high)[c >> k & 1][k] for k in range(3)] for c in range(8)])
        seeds = [
            (np.atleast_2d(np.asarray(shape.aabb_center, dtype=float)), float(shape.aabb_radius)),
            (corners, 0.0),
        ]
        carried = [_carry(model, axes, obj, points, ball, lower, upper) for points, ball in seeds]
        radii = np.min([speed for speed, _ in carried], axis=0)  # each bounds the speed
        bounds.append(GeometryReach(radii=radii, hulls=tuple(hull for _, hull in carried)))
    return bounds


def _carry(
    model: Any,
    axes: list[tuple[bool, FloatArray]],
    obj: Any,
    points: FloatArray,
    ball: float,
    lower: FloatArray,
    upper: FloatArray,
) -> tuple[FloatArray, Hull]:
    """Carry a bound (``points`` in the geometry's frame, ``ball``) up to the world.

    Returns the per-joint radii (see :class:`GeometryReach`) and the world hull.
    """
    placement = obj.placement
    points = points @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
    radii = np.zeros(len(axes))
    joint = obj.parentJoint
    while joint > 0:
        i = joint - 1
        prismatic, axis = axes[i]
        if prismatic:
            radii[i] = 1.0
            points = np.vstack([points + lower[i] * axis, points + upper[i] * axis])
        else:
            distance = float(_distance_from_axis(points, axis).max())
            radii[i] = distance + ball
            ball += distance
            points = np.outer(points @ axis, axis)
        placement = model.jointPlacements[joint]
        points = points @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
        joint = model.parents[joint]
    return radii, Hull(points=points, ball=ball)


def relative_radii(
    model: Any, collision_model: Any, pairs: Sequence[tuple[int, int]], geometry_radii: ArrayLike
) -> FloatArray:
    """``(P, nj)`` how fast each pair's distance may change per joint speed [m/rad, m/m].

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: its geometry model.
        pairs: ``(geometry index, geometry index)`` per pair.
        geometry_radii: ``(G, nj)`` each geometry's motion radius about each joint, 0 for the
            joints that do not carry it (:attr:`cpr_kin.bounds.reach.GeometryReach.radii`).

    A joint carrying both geometries or neither counts 0; one carrying only one of them,
    that geometry's radius about it.
    """
    joints = model.njoints - 1
    carried = np.zeros((len(collision_model.geometryObjects), joints), dtype=bool)
    for g, obj in enumerate(collision_model.geometryObjects):
        joint = obj.parentJoint
        while joint > 0:
            carried[g, joint - 1] = True
            joint = model.parents[joint]
    radii = np.asarray(geometry_radii, dtype=float)
    if not len(pairs):
        return np.zeros((0, joints))
    a, b = np.asarray(pairs, dtype=np.intp).T
    only_a, only_b = carried[a] & ~carried[b], carried[b] & ~carried[a]
    return np.where(only_a, radii[a], 0.0) + np.where(only_b, radii[b], 0.0)
