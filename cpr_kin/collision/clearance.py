"""What a clearance query returns: signed distances per pair, per group, per configuration.

Distances are signed: negative values are penetration depths [m]. The clearance of a group
(:data:`cpr_kin.GROUPS`) is the smallest distance between any of its geometries and any
obstacle.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.model.robot import GROUPS, RobotGeometry

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


@dataclass(frozen=True)
class PairDistance:
    """Signed distance of one robot geometry to one obstacle.

    Attributes:
        robot_geometry: robot geometry name (e.g. ``"arm"``).
        obstacle: obstacle name.
        group: collision group of the robot geometry.
        distance_m: signed distance [m]; negative when they overlap.
        point_on_robot: closest point on the robot geometry, world frame [m].
        point_on_obstacle: closest point on the obstacle, world frame [m].

    """

    robot_geometry: str
    obstacle: str
    group: str
    distance_m: float
    point_on_robot: FloatArray
    point_on_obstacle: FloatArray

    @classmethod
    def of(
        cls, result: Any, geometry: RobotGeometry, obstacle: str, distance_m: float, voxels: bool
    ) -> PairDistance:
        """The pair's distance from coal's ``DistanceResult`` of robot (first) and obstacle.

        coal gives an OcTree's point first, as first or second shape: for ``voxels`` they swap.
        """
        near = [np.array(result.getNearestPoint1()), np.array(result.getNearestPoint2())]
        if voxels:
            near.reverse()
        return cls(geometry.name, obstacle, geometry.group, distance_m, near[0], near[1])


@dataclass(frozen=True)
class Clearance:
    """Clearance of one configuration.

    Attributes:
        q: the configuration [rad, m].
        pairs: every robot-obstacle pair with its distance and closest points.
        group_clearance_m: smallest distance per group, keyed by group name [m]
            (``inf`` without obstacles).

    """

    q: FloatArray
    pairs: tuple[PairDistance, ...]
    group_clearance_m: dict[str, float]

    @property
    def min_clearance_m(self) -> float:
        """Smallest distance over every pair [m]."""
        return min(self.group_clearance_m.values())

    @property
    def closest(self) -> PairDistance | None:
        """The closest robot-obstacle pair, or ``None`` without obstacles."""
        return min(self.pairs, key=lambda p: p.distance_m) if self.pairs else None

    def violating_groups(self, margin_m: float) -> tuple[str, ...]:
        """Groups closer than ``margin_m`` [m] to an obstacle, in :data:`GROUPS` order."""
        return tuple(g for g in GROUPS if self.group_clearance_m[g] < margin_m)


@dataclass(frozen=True)
class BatchClearance:
    """Per-group clearance of many configurations.

    Attributes:
        clearance_m: ``(N, 2)`` smallest distance per group [m], columns in :data:`GROUPS`
            order (``effector``, ``links``).
        closest_pair: ``(N, 2)`` index into :attr:`CollisionWorld.pairs` of the closest pair
            per group (``-1`` without obstacles).

    """

    clearance_m: FloatArray
    closest_pair: IntArray

    @property
    def min_clearance_m(self) -> FloatArray:
        """``(N,)`` smallest distance over both groups [m]."""
        return np.asarray(self.clearance_m.min(axis=1))
