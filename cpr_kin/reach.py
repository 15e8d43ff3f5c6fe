"""Conservative bounds on where each robot geometry can be, over all configurations.

Each collision geometry is bounded by the convex hull of a few points plus a ball, carried
up the kinematic tree: a prismatic joint sweeps the points over its travel; a revolute joint
(whose angle is free) folds them onto its axis and adds their largest distance from the axis
to the ball. Along the way, the largest distance of the set from each revolute axis bounds
how fast the geometry moves when that joint turns (:func:`cpr_kin.motion_radii`). At the
root the set is a segment on the first joint's axis plus a ball: a capsule that contains the
geometry in every configuration.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class GeometryReach:
    """Bounds for one collision geometry.

    Attributes:
        radii: per joint, the largest distance of the geometry from that joint's axis
            (revolute) or 1 (prismatic), 0 for joints that do not carry it [m or m/m].
        points: ``(K, 3)`` world points whose convex hull, grown by ``ball``, contains the
            geometry in every configuration [m].
        ball: the growth [m].
    """

    radii: FloatArray
    points: FloatArray
    ball: float


def _joint_axis(joint: Any) -> tuple[bool, FloatArray]:
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
    axes = [_joint_axis(model.joints[k]) for k in range(1, model.njoints)]
    bounds = []
    for obj in collision_model.geometryObjects:
        shape = obj.geometry
        shape.computeLocalAABB()
        points = np.atleast_2d(obj.placement.act(np.asarray(shape.aabb_center, dtype=float)))
        ball = float(shape.aabb_radius)
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
        bounds.append(GeometryReach(radii=radii, points=points, ball=ball))
    return bounds
