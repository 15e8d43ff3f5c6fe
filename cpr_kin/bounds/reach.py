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
    children: dict[int, list[int]] = {}
    for joint in range(1, model.njoints):
        children.setdefault(model.parents[joint], []).append(joint)
    axes = [joint_axis(model.joints[k]) for k in range(1, model.njoints)]
    chain = _Chain(model, axes, lower, upper, children)
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
        placed = [
            (points @ np.asarray(obj.placement.rotation).T + obj.placement.translation, b)
            for points, b in seeds
        ]
        carried = [chain.up(obj.parentJoint, points, ball) for points, ball in placed]
        radii = np.min([speed for speed, _ in carried], axis=0)  # each bounds the speed
        below = np.min([chain.down(obj.parentJoint, points, ball) for points, ball in placed], axis=0)
        bounds.append(GeometryReach(radii=radii, hulls=tuple(hull for _, hull in carried), below=below))
    return bounds


@dataclass(frozen=True)
class _Chain:
    """A model's joints as the bounds cross them: each one's (is prismatic, axis), its limits and children."""

    model: Any
    axes: list[tuple[bool, FloatArray]]
    lower: FloatArray
    upper: FloatArray
    children: dict[int, list[int]]

    def through(
        self, joint: int, points: FloatArray, ball: float, sign: float
    ) -> tuple[float, FloatArray, float]:
        """A bound (``points`` in ``joint``'s frame, ``ball``) moved by every value of the joint.

        Returns its radius about the joint (1 for a prismatic one) and the bound of every
        position: slid along the travel (``sign`` -1: the frame moves, not the bound), or turned
        about the axis (folded onto it, the ball grown by the points' distance from it).
        """
        i = joint - 1
        prismatic, axis = self.axes[i]
        if prismatic:
            ends = (points + sign * self.lower[i] * axis, points + sign * self.upper[i] * axis)
            return 1.0, np.vstack(ends), ball
        distance = float(_distance_from_axis(points, axis).max())
        return distance + ball, np.outer(points @ axis, axis), ball + distance

    def up(self, joint: int, points: FloatArray, ball: float) -> tuple[FloatArray, Hull]:
        """A bound in ``joint``'s frame carried up to the world: radii per joint (``radii``), world hull."""
        radii = np.zeros(len(self.axes))
        while joint > 0:
            radii[joint - 1], points, ball = self.through(joint, points, ball, 1.0)
            placement = self.model.jointPlacements[joint]
            points = points @ np.asarray(placement.rotation).T + np.asarray(placement.translation)
            joint = self.model.parents[joint]
        return radii, Hull(points=points, ball=ball)

    def down(self, joint: int, points: FloatArray, ball: float) -> FloatArray:
        """A bound in ``joint``'s frame carried down every chain below it: its distance from each axis."""
        below = np.full(len(self.axes), np.inf)
        children = self.children
        stack = [(child, points, ball) for child in children.get(joint, [])]
        while stack:
            joint, points, ball = stack.pop()
            placement = self.model.jointPlacements[joint]  # into the joint's frame, before its motion
            points = (points - np.asarray(placement.translation)) @ np.asarray(placement.rotation)
            below[joint - 1], points, ball = self.through(joint, points, ball, -1.0)
            stack.extend((child, points, ball) for child in children.get(joint, []))
        return below


def relative_radii(
    model: Any,
    collision_model: Any,
    pairs: Sequence[tuple[int, int]],
    reach: Sequence[GeometryReach] | None = None,
) -> FloatArray:
    """``(P, nj)`` how fast each pair's distance may change per joint speed [m/rad, m/m].

    Args:
        model: the robot's Pinocchio model (one-degree-of-freedom joints).
        collision_model: its geometry model.
        pairs: ``(geometry index, geometry index)`` per pair.
        reach: each geometry's bounds (:func:`geometry_reach`); default: within ``model``'s
            position limits.

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
    if reach is None:
        reach = geometry_reach(model, collision_model, model.lowerPositionLimit, model.upperPositionLimit)
    radii, below = np.array([r.radii for r in reach]), np.array([r.below for r in reach])
    a, b = np.asarray(pairs, dtype=np.intp).T
    only_a, only_b = carried[a] & ~carried[b], carried[b] & ~carried[a]
    turning_a, turning_b = np.minimum(radii[a], below[b]), np.minimum(radii[b], below[a])
    return np.where(only_a, turning_a, 0.0) + np.where(only_b, turning_b, 0.0)
