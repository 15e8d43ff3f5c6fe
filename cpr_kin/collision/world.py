"""Robot-versus-obstacle clearance with coal, for one configuration or a batch.

A :class:`CollisionWorld` adds the obstacles to a copy of the robot's Pinocchio geometry
model and registers robot-obstacle pairs only (the robot never tests itself). Distances are
signed: negative values are penetration depths (into a point cloud's voxels, at most a voxel's).
A concave link is measured on its exact mesh where its hull comes near (:mod:`cpr_kin.shapes.exact_pairs`).
The clearance of a group is the smallest distance between any of its geometries and any
obstacle. Distances are accurate to about 1e-6 of their size (coal's GJK tolerance). Among many
obstacles, a query's cost follows those within reach (:mod:`cpr_kin.collision.reach_tiers`).
"""

from __future__ import annotations

import copy
from collections.abc import Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.bounds.obstacle_bounds import obstacle_arrays
from cpr_kin.bounds.pair_bounds import PairBounds
from cpr_kin.collision.clearance import BatchClearance, Clearance, PairDistance
from cpr_kin.collision.closest_pairs import closest_pairs
from cpr_kin.collision.coal_pools import default_threads
from cpr_kin.collision.decisive import below_coal, coal_error_m
from cpr_kin.collision.obstacle_tests import ObstacleTests
from cpr_kin.collision.reach_tiers import ReachTiers
from cpr_kin.collision.robot_reach import PairBoundsSets, PairReach, WorldPairs
from cpr_kin.collision.touch_links import checked_pairs
from cpr_kin.collision.world_self_pairs import world_self_collision
from cpr_kin.common.errors import CprKinError
from cpr_kin.model.robot import GROUPS, Robot
from cpr_kin.shapes.exact_pairs import ExactPairs
from cpr_kin.shapes.obstacles import Obstacle, checked_obstacles

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class CollisionWorld:
    """The robot among static obstacles, ready for repeated distance queries.

    Args:
        robot: the robot (its collision geometry model is copied, never modified).
        obstacles: the obstacles; their names must be unique.
        num_threads: threads of the parallel checks of the robot's own pairs (default:
            :func:`~cpr_kin.collision.coal_pools.default_threads`); coal tests the obstacles'
            pairs one configuration at a time (:mod:`cpr_kin.collision.obstacle_tests`).
        allowed_pairs: link pairs of the robot allowed to touch (a scene's), beyond its SRDF's;
            an obstacle's own ``touch_links`` may touch it (:mod:`cpr_kin.collision.touch_links`).
        self_margin_m: the self margin the world's user holds the robot's own pairs to [m]: a
            pair closer than it by design (:attr:`cpr_kin.Robot.close_pairs`, its largest
            distance below it) is held to contact only, its distance counting the margin as
            kept (:attr:`cpr_kin.collision.self_collision.SelfCollision.allowance_m`). Default 0: none is.

    Attributes:
        self_collision: the robot's own pairs (:mod:`cpr_kin.collision.self_collision`), false when
            it has none.

    """

    def __init__(
        self,
        robot: Robot,
        obstacles: Sequence[Obstacle],
        *,
        num_threads: int | None = None,
        allowed_pairs: Sequence[tuple[str, str]] = (),
        self_margin_m: float = 0.0,
    ) -> None:
        if not (np.isfinite(self_margin_m) and self_margin_m >= 0.0):
            raise CprKinError(f"self_margin_m = {self_margin_m} m must be a finite distance >= 0")
        self.robot = robot
        self.obstacles = checked_obstacles(obstacles)
        self.num_threads = num_threads or default_threads()
        model = robot.collision_model.copy()
        obstacle_ids = []
        for obstacle in self.obstacles:
            obj = pin.GeometryObject(
                f"obstacle:{obstacle.name}", 0, 0, obstacle.placement, obstacle.geometry()
            )
            obstacle_ids.append(model.addGeometryObject(obj))
        pairs = checked_pairs(robot, self.obstacles)  # but each obstacle's touch_links
        for g, k in pairs:
            model.addCollisionPair(pin.CollisionPair(g, obstacle_ids[k]))
        self.geometry_model = model
        self._pairs = pairs
        self._pair_group = np.array(
            [GROUPS.index(robot.geometries[g].group) for g, _ in pairs], dtype=np.int64
        )
        self._data = robot.model.createData()
        self._all = model.createData()
        self._exact = ExactPairs(model, robot.exact_meshes)
        self._tests = ObstacleTests(robot.model, model, self._exact)
        self._shapes = obstacle_arrays(self.obstacles)  # every pair set's bounds share them
        of = WorldPairs(robot, self.obstacles, self._pairs, self._shapes)
        self._bounds, self._reach = PairBoundsSets(of), PairReach(of)
        self._within: dict[float, tuple[IntArray, PairBounds | None]] = {}
        self._tiers = ReachTiers(self._reach.sphere_m, self._pair_group, self._bounds)
        self.self_collision = world_self_collision(robot, allowed_pairs, self_margin_m, self.num_threads)

    def on_hulls(self) -> CollisionWorld:
        """The world with its robot's hulls deciding alone, sharing its data (use one at a time)."""
        hulls = copy.copy(self)
        hulls.robot = self.robot.on_hulls
        hulls._exact = ExactPairs(self.geometry_model, {})
        hulls._tests = self._tests.on_hulls()
        hulls.self_collision = self.self_collision.on_hulls()
        return hulls

    @property
    def pairs(self) -> tuple[tuple[str, str, str], ...]:
        """``(robot geometry, obstacle, group)`` of every pair, in query order."""
        geoms = self.robot.geometries
        return tuple((geoms[g].name, self.obstacles[k].name, geoms[g].group) for g, k in self._pairs)

    def clearance(self, q: ArrayLike) -> Clearance:
        """Signed distance of every robot-obstacle pair at configuration ``q`` [rad, m].

        On the exact meshes for each pair that may be its group's closest; the others' the hulls'.
        """
        q_arr = self.robot.configuration(q, check_limits=False)
        pin.computeDistances(self.robot.model, self._data, self.geometry_model, self._all, q_arr)
        pairs = []
        group_min = {g: float("inf") for g in GROUPS}
        hulls = np.array([r.min_distance for r in self._all.distanceResults])
        ask = self._exact.may_be_closest(hulls, self._pair_group)
        for p, ((g, k), result) in enumerate(zip(self._pairs, self._all.distanceResults, strict=True)):
            geometry, distance = self.robot.geometries[g], float(result.min_distance)
            measured = self._exact.measured(self._all, p, distance) if ask[p] else None
            if measured is not None:
                result, distance = measured, max(float(measured.min_distance), distance)
            voxels = self.obstacles[k].shape == "voxels"
            pairs.append(PairDistance.of(result, geometry, self.obstacles[k].name, distance, voxels))
            group_min[geometry.group] = min(group_min[geometry.group], distance)
        return Clearance(q=q_arr, pairs=tuple(pairs), group_clearance_m=group_min)

    def clearance_batch(self, q: ArrayLike) -> BatchClearance:
        """Per-group clearance of configurations ``q`` of shape ``(N, nq)`` [rad, m].

        One coal query per group and configuration, each returning its closest pair; joint
        limits are not checked (callers sampling a curve pass in-range values).
        """
        batch = self._check_batch(q)
        clearance = np.full((len(batch), len(GROUPS)), np.inf)
        closest = np.full((len(batch), len(GROUPS)), -1, dtype=np.int64)
        for group_index in range(len(GROUPS)):
            clearance[:, group_index], closest[:, group_index] = self.group_clearance(batch, group_index)
        return BatchClearance(clearance_m=clearance, closest_pair=closest)

    def group_clearance(
        self,
        q: ArrayLike,
        group_index: int,
        exact_below_m: float = np.inf,
        per_pair_m: FloatArray | None = None,
    ) -> tuple[FloatArray, IntArray]:
        """Clearance [m] of group ``GROUPS[group_index]`` at configurations ``q`` ``(N, nq)``, by coal.

        Also the index of the closest pair per configuration; ``inf`` and ``-1`` for a group
        with no pair. coal's distance of the closest pair; the pairs are visited in the
        order of their bounds and only those that may be closest are computed
        (:func:`cpr_kin.collision.closest_pairs.closest_pairs`). The bounds are the group's columns of
        every pair's (:meth:`pair_bounds`, ``per_pair_m`` where the caller has them). A distance
        at or above ``exact_below_m`` [m] may be reported as that (a lower bound).
        """
        batch = self._check_batch(q)
        pairs = self._tiers.columns(group_index)
        if not pairs.size:
            return np.full(len(batch), np.inf), np.full(len(batch), -1, dtype=np.int64)
        bounds = self._tiers.group_bounds(batch, group_index) if per_pair_m is None else per_pair_m[:, pairs]
        model, data = self.robot.model, self._data
        return closest_pairs(
            model,
            data,
            self.geometry_model,
            self._all,
            batch,
            bounds,
            pairs,
            exact=self._exact,
            exact_below_m=exact_below_m,
        )

    def pair_bounds(self, q: ArrayLike) -> FloatArray:
        """``(N, P)`` every pair's lower bound [m] at ``q``: its capsule bound or its reach, the larger.

        Capsule bounds: :mod:`cpr_kin.bounds.pair_bounds`; reach: :mod:`cpr_kin.collision.reach_tiers`.
        """
        batch = self._check_batch(q)
        if not self._pairs:
            return np.empty((len(batch), 0))
        return np.maximum(self._bounds((True,) * len(self._pairs))(batch), self._reach.sphere_m)

    def clearance_lower_bounds(self, q: ArrayLike, per_pair_m: FloatArray | None = None) -> FloatArray:
        """``(N, len(GROUPS))`` lower bounds [m] of each group's clearance at ``q`` ``(N, nq)``.

        The least of its pairs' bounds (:meth:`pair_bounds`, ``per_pair_m`` where the caller has
        them), less coal's error (:func:`~cpr_kin.collision.decisive.below_coal`): at most
        :meth:`clearance_batch`'s where positive; ``-inf`` where the bounding shapes overlap (nothing
        is known), ``inf`` for a group with no pair.
        """
        least = self._tiers.least(self._check_batch(q), len(GROUPS), per_pair_m)
        bounds, finite = least.copy(), np.isfinite(least)
        bounds[finite] = below_coal(least[finite])
        bounds[bounds <= 0.0] = -np.inf
        return bounds

    def min_clearance_batch(self, q: ArrayLike, below_m: float | None = None) -> tuple[FloatArray, IntArray]:
        """Smallest distance over every pair [m] and the index of that pair, ``(N,)`` each.

        Only the pairs that may be closest are computed (:func:`cpr_kin.collision.closest_pairs`, on
        the pair bounds). With ``below_m`` [m], only those closer than that too (of the pairs
        whose reach, :mod:`cpr_kin.bounds.reach`, comes within it): one below ``below_m`` exact (a link's
        mesh may give its hull's, a lower bound: :meth:`~cpr_kin.shapes.exact_pairs.ExactPairs.settled`),
        a larger one ``inf`` with pair ``-1`` (what a caller wants who asks where a margin is violated).
        """
        batch = self._check_batch(q)
        if below_m is None:
            below_m = np.inf
        elif not np.isfinite(below_m):
            raise CprKinError(f"distance bound {below_m} m must be finite")
        pairs, bounds = self._pairs_within(below_m)
        values = np.empty((len(batch), 0)) if bounds is None else bounds(batch)
        model, data = self.robot.model, self._data
        return closest_pairs(
            model, data, self.geometry_model, self._all, batch, values, pairs, below_m, exact=self._exact
        )

    def _check_batch(self, q: ArrayLike) -> FloatArray:
        batch = np.asarray(q, dtype=float)
        if batch.ndim != 2 or batch.shape[1] != self.robot.nq:
            raise CprKinError(f"configurations of shape {batch.shape}; expected (N, {self.robot.nq})")
        if not np.isfinite(batch).all():
            raise CprKinError("configurations contain NaN or inf")
        return batch

    def margin_violated(self, q: ArrayLike, margin_m: float, ordered: bool = False) -> NDArray[np.bool_]:
        """``(N,)`` whether any robot geometry is closer than ``margin_m`` [m] to an obstacle.

        A yes/no check run by coal's collision test with ``margin_m`` as security margin.
        Pairs that cannot come within the margin in any configuration (their reach capsule is
        farther, :class:`~cpr_kin.collision.robot_reach.PairReach`) are not tested, and coal tests a
        configuration's pair only where its cheap bound (:mod:`cpr_kin.bounds.pair_bounds`,
        computed for the whole batch at once) does not put it certainly farther than the
        margin (:mod:`cpr_kin.collision.obstacle_tests`). Distances within coal's error of the
        margin (:func:`~cpr_kin.collision.decisive.coal_error_m`) always go to coal.

        With ``ordered``, the configurations are decided in order up to the first violated
        one, and those after it are reported violated without a test: what an edge check
        needs (where an edge is first blocked), in a fraction of coal's tests.
        """
        batch = self._check_batch(q)
        if not (np.isfinite(margin_m) and margin_m >= 0.0):
            raise CprKinError(f"safety margin {margin_m} m must be a finite number >= 0")
        pairs, bounds = self._pairs_within(margin_m)
        if bounds is None or not len(batch):
            return np.zeros(len(batch), dtype=bool)
        uncertain = bounds.pairs_below(batch, float(margin_m + coal_error_m(margin_m)))
        return self._tests.violated(batch, uncertain, pairs, margin_m, ordered)

    def keeps_clearance(
        self, q: ArrayLike, margin_m: float, self_margin_m: float, ordered: bool = False
    ) -> NDArray[np.bool_]:
        """``(N,)`` whether each configuration keeps its clearances: to obstacles and its own links.

        ``margin_m`` [m] from every obstacle (:meth:`margin_violated`), then, only where that
        holds, ``self_margin_m`` [m] between the robot's own checked pairs. With ``ordered``,
        exact up to the first configuration that does not keep them; those after it are
        reported so, without the tests an unordered check would make there
        (:meth:`margin_violated`, :meth:`~cpr_kin.collision.self_collision.SelfCollision.violated`).
        """
        batch = np.asarray(q, dtype=float)  # margin_violated checks it
        free = ~self.margin_violated(batch, margin_m, ordered)
        if self.self_collision and free.any():
            free[free] = ~self.self_collision.violated(batch[free], self_margin_m, ordered)
        return free

    def _pairs_within(self, distance_m: float) -> tuple[IntArray, PairBounds | None]:
        """The pairs whose reach comes within ``distance_m`` [m] (their indices) and their bounds.

        The bounds' columns are those pairs, in order (``None``: no pair). Looked up once per
        distance (a plan asks a few margins many times).
        """
        if distance_m not in self._within:
            near = self._reach.within(distance_m)
            bounds = self._bounds(tuple(near.tolist())) if near.any() else None
            self._within[distance_m] = (np.flatnonzero(near), bounds)
        return self._within[distance_m]
