"""A robot's reach bounds and capsules (:mod:`cpr_kin.bounds`), once per robot; its least obstacle distances.

The least distance of each robot geometry and obstacle pair over every configuration bounds
what a world's margin test needs to ask of that pair (:class:`PairReach`: coal's, asked only of
the pairs a cheaper bound cannot rule out).
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass
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
BoolArray = NDArray[np.bool_]


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


@dataclass(frozen=True, eq=False)
class WorldPairs:
    """What a world's pair bounds are built of.

    Attributes:
        robot: the robot.
        obstacles: the obstacles.
        pairs: ``(geometry index, obstacle index)`` of every checked pair.
        shapes: the obstacles' bounds (:func:`~cpr_kin.bounds.obstacle_bounds.obstacle_arrays`).
    """

    robot: Robot
    obstacles: Sequence[Obstacle]
    pairs: Sequence[tuple[int, int]]
    shapes: ObstacleArrays


class PairBoundsSets:
    """:func:`robot_pair_bounds` of subsets of a world's pairs (``of``), each built once.

    Holds no reference to the world that owns it: a world's parts sharing it make no reference
    cycle, so a world's arrays are freed when it is dropped, not at the next garbage collection.
    """

    def __init__(self, of: WorldPairs) -> None:
        self._of = of
        self._built: dict[tuple[bool, ...], PairBounds] = {}

    def __call__(self, active: tuple[bool, ...]) -> PairBounds:
        """The pair bounds of the pairs flagged true (one flag per pair, in ``pairs``' order)."""
        if active not in self._built:
            of = self._of
            pairs = [pair for pair, on in zip(of.pairs, active, strict=True) if on]
            self._built[active] = robot_pair_bounds(of.robot, of.obstacles, pairs, of.shapes)
        return self._built[active]


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


_ROBOT_SEGMENTS: weakref.WeakKeyDictionary[Robot, tuple[tuple[FloatArray, FloatArray], ...]] = (
    weakref.WeakKeyDictionary()
)


def _robot_segments(robot: Robot) -> tuple[tuple[FloatArray, FloatArray], ...]:
    """Per robot geometry, its swept capsules: segments ``(H, 2, 3)`` and radii ``(H,)`` [m]; once a robot."""
    if robot not in _ROBOT_SEGMENTS:
        reach, segments = robot_reach(robot), []
        for geometry in robot.geometries:
            capsules = [hull.capsule() for hull in reach[geometry.index].hulls]
            ends = np.array([[c - h * a, c + h * a] for c, a, h, _ in capsules]).reshape(-1, 2, 3)
            segments.append((ends, np.array([r for _, _, _, r in capsules], dtype=float)))
        _ROBOT_SEGMENTS[robot] = tuple(segments)
    return _ROBOT_SEGMENTS[robot]


def sphere_reach_distances(
    robot: Robot, shapes: ObstacleArrays, pairs: Sequence[tuple[int, int]]
) -> FloatArray:
    """Per ``(geometry index, obstacle index)`` pair, a cheaper lower bound of its least distance [m].

    Of each of the geometry's swept capsules (:func:`pair_reach_distances`' shapes), the
    distance from its segment to the centre of the obstacle's bounding sphere (``shapes``,
    :func:`~cpr_kin.bounds.obstacle_bounds.obstacle_arrays`), less both radii; the largest. Where
    positive, at most :func:`pair_reach_distances`'s; every pair in a few array operations per
    geometry, where coal takes a query per pair and capsule.
    """
    segments = _robot_segments(robot)
    distances = np.full(len(pairs), -np.inf)
    geometry = np.array([g for g, _ in pairs], dtype=np.int64)
    obstacle = np.array([k for _, k in pairs], dtype=np.int64)
    for g in set(geometry.tolist()):
        rows = np.flatnonzero(geometry == g)
        centres, reach = shapes.centre[obstacle[rows]], shapes.reach[obstacle[rows]]
        ends, radii = segments[g]
        for (a, b), radius in zip(ends, radii, strict=True):
            along = b - a
            length2 = float(along @ along)
            t = np.clip((centres - a) @ along / length2, 0.0, 1.0) if length2 > 0.0 else np.zeros(len(rows))
            apart = np.linalg.norm(centres - (a + t[:, None] * along), axis=1) - radius - reach
            distances[rows] = np.maximum(distances[rows], apart)
    return distances


class PairReach:
    """Lower bounds of a world's pairs' (``of``) distances in any configuration, coal's where asked.

    Attributes:
        sphere_m: ``(P,)`` every pair's :func:`sphere_reach_distances`.
    """

    def __init__(self, of: WorldPairs) -> None:
        self._robot, self._obstacles, self._pairs = of.robot, of.obstacles, list(of.pairs)
        self.sphere_m = sphere_reach_distances(of.robot, of.shapes, of.pairs)
        self._coal = np.full(len(self._pairs), np.nan)  # pair_reach_distances', where computed

    def within(self, distance_m: float) -> BoolArray:
        """``(P,)`` whether each pair's :func:`pair_reach_distances` is at most ``distance_m`` [m].

        coal computes it (once) only for the pairs whose :attr:`sphere_m` is at most
        ``max(distance_m, 0)``: a pair the sphere puts farther is farther (a sphere that reaches
        the capsule, at most 0, holds every pair that may overlap). Every pair is within ``inf``.
        """
        if distance_m == np.inf:
            return np.ones(len(self._pairs), dtype=bool)
        maybe = self.sphere_m <= max(distance_m, 0.0)
        asked = np.flatnonzero(maybe & np.isnan(self._coal))
        if asked.size:
            chosen = [self._pairs[p] for p in asked.tolist()]
            self._coal[asked] = pair_reach_distances(self._robot, self._obstacles, chosen)
        return np.asarray(maybe & (self._coal <= distance_m))
