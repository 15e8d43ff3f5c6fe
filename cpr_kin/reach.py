"""Conservative bounds on where each robot geometry can be, over all configurations.

Each collision geometry is bounded by the convex hull of a few points plus a ball (its
bounding box's centre and radius, and separately its bounding box's corners), carried up
the kinematic tree: a prismatic joint sweeps the points over its travel; a revolute joint
(whose angle is free) folds them onto its axis and adds their largest distance from the axis
to the ball. Along the way, the largest distance of the set from each revolute axis bounds
how fast the geometry moves when that joint turns (:func:`cpr_kin.motion_radii`). At the
root the set is a segment on the first joint's axis plus a ball: a capsule that contains the
geometry in every configuration.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from cpr_kin.obstacles import Obstacle
    from cpr_kin.robot import Robot

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


_ROBOT_REACH: weakref.WeakKeyDictionary[Robot, tuple[GeometryReach, ...]] = weakref.WeakKeyDictionary()


def robot_reach(robot: Robot) -> tuple[GeometryReach, ...]:
    """:func:`geometry_reach` of ``robot``'s collision geometries within its joint ranges.

    Computed once per robot (a few milliseconds, asked for by every problem built, edge
    checked and trajectory verified); a :class:`~cpr_kin.Robot` does not change.
    """
    if robot not in _ROBOT_REACH:
        limits = robot.limits
        reach = geometry_reach(robot.model, robot.collision_model, limits.lower, limits.upper)
        _ROBOT_REACH[robot] = tuple(reach)
    return _ROBOT_REACH[robot]


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


_ROBOT_SWEPT: weakref.WeakKeyDictionary[Robot, tuple[tuple[tuple[Any, Any], ...], ...]] = (
    weakref.WeakKeyDictionary()
)


def _robot_swept(robot: Robot) -> tuple[tuple[tuple[Any, Any], ...], ...]:
    """Per robot geometry (``robot.geometries``' order), its swept capsules as coal shapes, placed.

    Built once per robot, as :func:`robot_reach`: every problem's world asks for them.
    """
    import coal
    import pinocchio as pin

    if robot not in _ROBOT_SWEPT:
        reach, swept = robot_reach(robot), []
        for geometry in robot.geometries:
            placed = []
            for hull in reach[geometry.index].hulls:
                centre, axis, half, radius = hull.capsule()
                rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), axis).matrix()
                placed.append((coal.Capsule(radius, 2 * half), coal.Transform3s(rotation, centre)))
            swept.append(tuple(placed))
        _ROBOT_SWEPT[robot] = tuple(swept)
    return _ROBOT_SWEPT[robot]


def pair_reach_distances(
    robot: Robot, obstacles: Sequence[Obstacle], pairs: Sequence[tuple[int, int]]
) -> FloatArray:
    """Per ``(geometry index, obstacle index)`` pair, a lower bound of its distance in any configuration [m].

    Each robot geometry stays inside a capsule around the first joint's axis
    (:func:`geometry_reach`); the distance from that capsule to the obstacle, by coal,
    bounds the pair's distance from below, whatever the joints do.
    """
    import coal

    swept = _robot_swept(robot)
    placed = {
        k: (
            obstacles[k].geometry(),
            coal.Transform3s(obstacles[k].placement.rotation, obstacles[k].placement.translation),
        )
        for k in {k for _, k in pairs}
    }
    request, distances = coal.DistanceRequest(), []
    for g, k in pairs:
        shape, placement = placed[k]
        bound = -np.inf  # every hull gives a lower bound: keep the largest
        for capsule, transform in swept[g]:
            result = coal.DistanceResult()
            coal.distance(capsule, transform, shape, placement, request, result)
            bound = max(bound, result.min_distance)
        distances.append(bound)
    return np.array(distances)
