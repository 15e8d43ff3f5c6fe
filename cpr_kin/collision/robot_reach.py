"""A robot's reach bounds and capsules (:mod:`cpr_kin.bounds`), once per robot; its least obstacle distances.

The least distance of each robot geometry and obstacle pair over every configuration bounds
what a world's margin test needs to ask of that pair.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import KinematicChain
from cpr_kin.bounds.obstacle_bounds import ObstacleArrays
from cpr_kin.bounds.pair_bounds import KnownCapsules, PairBounds
from cpr_kin.bounds.reach import GeometryReach, geometry_reach

if TYPE_CHECKING:
    from cpr_kin.model.robot import Robot
    from cpr_kin.shapes.obstacles import Obstacle

FloatArray = NDArray[np.float64]


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


class RobotCapsules(NamedTuple):
    """What a robot's pair bounds (:class:`~cpr_kin.bounds.pair_bounds.PairBounds`) are built on, kept.

    Attributes:
        chain: its kinematic chain.
        known: its geometries' capsules fitted so far (:func:`~cpr_kin.bounds.pair_bounds.joint_capsules`).
    """

    chain: KinematicChain
    known: KnownCapsules


_ROBOT_CAPSULES: weakref.WeakKeyDictionary[Robot, RobotCapsules] = weakref.WeakKeyDictionary()


def robot_capsules(robot: Robot) -> RobotCapsules:
    """``robot``'s :class:`RobotCapsules`, once per robot: each world builds pair bounds for a few margins."""
    if robot not in _ROBOT_CAPSULES:
        _ROBOT_CAPSULES[robot] = RobotCapsules(KinematicChain.from_model(robot.model), {})
    return _ROBOT_CAPSULES[robot]


def robot_pair_bounds(
    robot: Robot, obstacles: Sequence[Obstacle], pairs: Sequence[tuple[int, int]], shapes: ObstacleArrays
) -> PairBounds:
    """:class:`~cpr_kin.bounds.pair_bounds.PairBounds` of ``robot``'s ``pairs`` with ``obstacles``.

    Bounded by ``shapes`` (their :func:`~cpr_kin.bounds.obstacle_bounds.obstacle_arrays`), on the
    robot's capsules and chain (:func:`robot_capsules`).
    """
    chain, known = robot_capsules(robot)
    model, collision = robot.model, robot.collision_model
    return PairBounds(model, collision, obstacles, pairs, chain=chain, known=known, shapes=shapes)


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
