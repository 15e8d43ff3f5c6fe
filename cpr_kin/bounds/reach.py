"""Conservative bounds on where each robot geometry can be, over all configurations.

Each collision geometry is bounded by the convex hull of a few points plus a ball (its
bounding box's centre and radius, and separately its bounding box's corners), carried up
the kinematic tree: a prismatic joint sweeps the points over its travel; a revolute joint
(whose angle is free) folds them onto its axis and adds their largest distance from the axis
to the ball. Along the way, the largest distance of the set from each revolute axis bounds
how fast the geometry moves when that joint turns (:func:`cpr_kin.motion_radii`). At the
root the set is a segment on the first joint's axis plus a ball: a capsule that contains the
geometry in every configuration. A pair's distance changes only by the joints that carry one
of its geometries and not the other, and a joint down the other's chain turns each about its
axis relative to the other: the nearer of the two to the axis bounds the change (carried down
the chain the same way: :func:`relative_radii`). These bounds of a robot, kept once per robot,
and of its geometries against obstacles: :mod:`cpr_kin.collision.robot_reach`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

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
        below: per joint down the chain from the geometry's link, the largest distance of the
            geometry from that joint's axis over the joints between them (revolute) or 1
            (prismatic); ``inf`` for the other joints [m or m/m]. A joint that turns another
            geometry turns it relative to this one as much as this one relative to it: their
            distance changes no faster than the smaller of the two radii (:func:`relative_radii`).
    """

    radii: FloatArray
    hulls: tuple[Hull, ...]
    below: FloatArray


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
        below = np.min(
            [_carry_down(model, axes, obj, points, ball, lower, upper) for points, ball in seeds], axis=0
        )
        bounds.append(GeometryReach(radii=radii, hulls=tuple(hull for _, hull in carried), below=below))
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


def _carry_down(
    model: Any,
    axes: list[tuple[bool, FloatArray]],
    obj: Any,
    points: FloatArray,
    ball: float,
    lower: FloatArray,
    upper: FloatArray,
) -> FloatArray:
    """Per joint down the chain from ``obj``'s link, its largest distance from its axis (``below``).

    The bound (``points`` in the geometry's frame, ``ball``) is carried down each joint's
    child chain: into a joint's frame, where its motion turns the bound about its axis (folded
    onto the axis, the ball grown by their distance) or slides it along its travel.
    """
    below = np.full(len(axes), np.inf)
    placement = obj.placement
    start = points @ np.asarray(placement.rotation).T + np.asarray(placement.translation), ball
    children: dict[int, list[int]] = {}
    for joint in range(1, model.njoints):
        children.setdefault(model.parents[joint], []).append(joint)
    stack = [(child, *start) for child in children.get(obj.parentJoint, [])]
    while stack:
        joint, points, ball = stack.pop()
        placement = model.jointPlacements[joint]  # into the joint's frame, before its motion
        points = (points - np.asarray(placement.translation)) @ np.asarray(placement.rotation)
        i = joint - 1
        prismatic, axis = axes[i]
        if prismatic:
            below[i] = 1.0
            points = np.vstack([points - lower[i] * axis, points - upper[i] * axis])
        else:
            distance = float(_distance_from_axis(points, axis).max())
            below[i] = distance + ball
            points, ball = np.outer(points @ axis, axis), ball + distance
        stack.extend((child, points, ball) for child in children.get(joint, []))
    return below


def relative_radii(
    model: Any, collision_model: Any, pairs: Sequence[tuple[int, int]], reach: Sequence[GeometryReach]
) -> FloatArray:
    """``(P, nj)`` how fast each pair's distance may change per joint speed [m/rad, m/m].

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: its geometry model.
        pairs: ``(geometry index, geometry index)`` per pair.
        reach: each geometry's bounds (:func:`geometry_reach`).

    A joint carrying both geometries or neither counts 0. One carrying only one of them counts
    that geometry's radius about it (:attr:`GeometryReach.radii`), or, where the joint lies down
    the other's chain, the other's distance from its axis if that is smaller
    (:attr:`GeometryReach.below`: the motion is relative).
    """
    joints = model.njoints - 1
    carried = np.zeros((len(collision_model.geometryObjects), joints), dtype=bool)
    for g, obj in enumerate(collision_model.geometryObjects):
        joint = obj.parentJoint
        while joint > 0:
            carried[g, joint - 1] = True
            joint = model.parents[joint]
    if not len(pairs):
        return np.zeros((0, joints))
    radii, below = np.array([r.radii for r in reach]), np.array([r.below for r in reach])
    a, b = np.asarray(pairs, dtype=np.intp).T
    only_a, only_b = carried[a] & ~carried[b], carried[b] & ~carried[a]
    turning_a, turning_b = np.minimum(radii[a], below[b]), np.minimum(radii[b], below[a])
    return np.where(only_a, turning_a, 0.0) + np.where(only_b, turning_b, 0.0)
