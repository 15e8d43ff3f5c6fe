"""A robot's own pairs split into near and far, and coal's test of them screened by their bounds.

The self-collision test (:meth:`cpr_kin.collision.self_collision.SelfCollision.violated`) asks coal
only about the pairs whose cheap bounds (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`) leave
them in doubt. Which pairs are mostly within a margin is a property of the robot: :class:`SelfScreen`
finds them, and :func:`robot_self_screen` builds it once per robot, set of pairs and
margin's rung (:func:`screen_threshold`; a collision world is built per plan, and the split
costs milliseconds on a robot of a few hundred pairs: ``docs/benchmarks.md``).
"""

from __future__ import annotations

import copy
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import sampled_configurations
from cpr_kin.bounds.self_bounds import SelfPairBounds
from cpr_kin.collision.closest_pairs import closest_pairs
from cpr_kin.collision.decisive import coal_error_m
from cpr_kin.collision.obstacle_pools import configure_pool, pool_collisions
from cpr_kin.shapes.exact_pairs import ExactPairs

if TYPE_CHECKING:
    from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
Pairs = tuple[tuple[int, int], ...]

PROBES = 256
"""Random configurations on which :class:`SelfScreen` finds the pairs that are always near."""
NEAR_SHARE = 0.3
"""Share of those in which a pair's bound is uncertain that makes it a near pair."""
SCREEN_THRESHOLDS_M = (0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
"""The distances [m] the probes may ask the bounds about (:func:`screen_threshold`): a few per
robot, each screen built once."""
TYPICAL_MARGIN_M = 0.01
"""The self margin [m] a :class:`ScreenedSelfTest` given no screen splits its pairs for (the
planner's default self margin)."""


def screen_threshold(margin_m: float) -> float:
    """The distance [m] a screen's probes ask about for a test of the self margin ``margin_m`` [m].

    Twice the margin (a check asks it plus its step), rounded up to :data:`SCREEN_THRESHOLDS_M`
    (the largest beyond them): a pair uncertain at a far larger distance than the test's is
    mostly certain at the test's, and belongs with the far pairs.
    """
    wanted = 2.0 * margin_m
    return next((t for t in SCREEN_THRESHOLDS_M if t >= wanted), SCREEN_THRESHOLDS_M[-1])


@dataclass(frozen=True)
class SelfScreen:
    """A robot's own pairs split into near and far, with their bounds.

    Some pairs of a serial arm are always close (a link and the one two joints down its
    chain, a few centimetres apart by design): bounding them first would only delay coal.
    The pairs are split on :data:`PROBES` seeded random configurations within the joint
    ranges: those whose bound is within the screen's distance in more than
    :data:`NEAR_SHARE` of them are *near*, the others *far* (``docs/tuning.md``, Kernels).

    Attributes:
        all_bounds: the bounds of every pair, in order.
        far_bounds: the bounds of the far pairs, in order.
        near: ``(P,)`` which pairs are near.
    """

    all_bounds: SelfPairBounds
    far_bounds: SelfPairBounds
    near: BoolArray

    @classmethod
    def build(
        cls, model: Any, geometry_model: Any, pairs: Sequence[tuple[int, int]], threshold_m: float
    ) -> SelfScreen:
        """The split of ``pairs`` (geometry indices of ``geometry_model``) on ``model``'s ranges.

        ``threshold_m``: the distance [m] the probes ask the bounds about (:func:`screen_threshold`).
        """
        probes = sampled_configurations(model, PROBES, np.random.default_rng(0))
        all_bounds = SelfPairBounds(model, geometry_model, pairs)
        uncertain = all_bounds(probes, threshold_m) <= threshold_m
        near = uncertain.mean(axis=0) > NEAR_SHARE
        near.setflags(write=False)
        far = SelfPairBounds(model, geometry_model, [p for p, n in zip(pairs, near, strict=True) if not n])
        return cls(all_bounds, far, near)


_SCREENS: weakref.WeakKeyDictionary[Robot, dict[tuple[Pairs, float], SelfScreen]] = (
    weakref.WeakKeyDictionary()
)


def robot_self_screen(robot: Robot, pairs: Pairs, margin_m: float) -> SelfScreen:
    """:meth:`SelfScreen.build` of ``robot``'s ``pairs`` for the self margin ``margin_m`` [m], built once.

    One per robot, pairs and :func:`screen_threshold`. A :class:`~cpr_kin.Robot` does not
    change; its screens go with it.
    """
    screens = _SCREENS.setdefault(robot, {})
    key = (pairs, screen_threshold(margin_m))
    if key not in screens:
        screens[key] = SelfScreen.build(robot.model, robot.collision_model, pairs, key[1])
    return screens[key]


class ScreenedSelfTest:
    """coal's yes/no self-collision test, screened by the pairs' bounds.

    The pairs are split once into near and far (:class:`SelfScreen`): the *near* go to coal
    at every configuration, the others (*far*) only at configurations
    where some far pair's bound is within the margin, and there only the far pairs whose
    bounds are within it in some configuration of the batch (a few of a thousand pairs on an
    arm whose hand has a dozen links). Each group has its own Pinocchio ``GeometryPool``, run
    in parallel over ``num_threads`` threads, stopping at a configuration's first hit. The
    answer is coal's on every pair.

    A pair's distance counts its allowance (:mod:`cpr_kin.bounds.close_pairs`): coal's distance plus
    ``allowance_m``, so a margin asks coal for that much less of the pair (never below contact).

    Args:
        model: the robot's Pinocchio model.
        geometry_model: its geometry model with the pairs added, in order.
        pairs: the pairs' geometry indices.
        num_threads: threads of coal's batches.
        allowance_m: ``(P,)`` each pair's allowance [m] (default: none).
        screen: the pairs' split and bounds (default: built for them at :data:`TYPICAL_MARGIN_M`;
            a robot's own is built once per margin's threshold, :func:`robot_self_screen`).
        exact: the pairs on the robot's exact meshes (:mod:`cpr_kin.shapes.exact_pairs`): what the
            hulls flag, the meshes decide; default: none decides.
    """

    def __init__(
        self,
        model: Any,
        geometry_model: Any,
        pairs: Sequence[tuple[int, int]],
        num_threads: int,
        allowance_m: FloatArray | None = None,
        screen: SelfScreen | None = None,
        exact: ExactPairs | None = None,
    ) -> None:
        self.model, self.geometry_model, self.num_threads = model, geometry_model, num_threads
        self._exact = exact if exact else None
        self.allowance_m = (
            np.zeros(len(pairs)) if allowance_m is None else np.asarray(allowance_m, dtype=float)
        )
        screen = screen or SelfScreen.build(model, geometry_model, pairs, screen_threshold(TYPICAL_MARGIN_M))
        near = screen.near
        self.all_bounds, self.far_bounds = screen.all_bounds, screen.far_bounds
        self.near_pairs = tuple(p for p, is_near in zip(pairs, near, strict=True) if is_near)
        self._near = near
        self._far_index = np.flatnonzero(~near)
        self._coal_state = _CoalState(np.zeros(len(pairs), dtype=bool), np.zeros(len(pairs)))

    def on_hulls(self) -> ScreenedSelfTest:
        """The test with the hulls deciding alone, sharing its pools and data (and what they are set to)."""
        hulls = copy.copy(self)
        hulls._exact = None
        return hulls

    def violated(self, batch: FloatArray, margin_m: float) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``batch``."""
        self._prepare(margin_m)
        hits = np.zeros(len(batch), dtype=bool)
        if self.near_pairs:
            hits[:] = self._coal(0, batch)
        if self.far_bounds.n_pairs:
            open_rows = np.flatnonzero(~hits)
            threshold = float(margin_m + coal_error_m(margin_m))
            doubtful = open_rows[self.far_bounds.any_below(batch[open_rows], threshold)]
            if doubtful.size:
                within = self.far_bounds(batch[doubtful], threshold) <= threshold
                self._switch_far(np.any(within, axis=0))
                hits[doubtful] = self._coal(1, batch[doubtful])
        return hits

    def _switch_far(self, doubtful: BoolArray) -> None:
        """Make the far pool test only the far pairs ``doubtful`` ``(P_far,)``: the rest clear the margin."""
        state = self._coal_state
        wanted = np.zeros_like(state.far_on)
        wanted[self._far_index[doubtful]] = True
        changed = np.flatnonzero(wanted != state.far_on).tolist()
        for gdata in state.pools[1].getGeometryDatas():
            for p in changed:
                (gdata.activateCollisionPair if wanted[p] else gdata.deactivateCollisionPair)(p)
        state.far_on = wanted

    def distances(self, batch: FloatArray) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair (index among all pairs), ``(N,)`` each, exactly.

        coal's distance of the closest pair, the pairs visited in the order of their bounds
        until no pair left can be closer (:func:`cpr_kin.collision.closest_pairs.closest_pairs`).
        """
        bounds = self.bounds(batch)
        return self._closest(batch, bounds, np.arange(bounds.shape[1]))

    def bounds(self, batch: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of every pair's distance (its capsules') at ``batch``."""
        return self.all_bounds(batch) + self.allowance_m

    def pair_bounds(self, batch: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` lower bounds [m] of pair ``pair``'s distance (its capsules') at ``batch``."""
        return self.all_bounds.column(batch, pair) + float(self.allowance_m[pair])

    def pair_distances(self, batch: FloatArray, pair: int, exact_below_m: float = np.inf) -> FloatArray:
        """``(N,)`` coal's distance [m] of pair ``pair`` (index among all pairs) at ``batch``.

        On the exact meshes where the hulls' distance is below ``exact_below_m`` [m].
        """
        unbounded, pairs = np.full((len(batch), 1), -np.inf), np.array([pair], dtype=np.int64)
        return self._closest(batch, unbounded, pairs, exact_below_m)[0]

    def _closest(
        self, batch: FloatArray, bounds: FloatArray, pairs: IntArray, exact_below_m: float = np.inf
    ) -> tuple[FloatArray, IntArray]:
        """:func:`~cpr_kin.collision.closest_pairs.closest_pairs` of ``pairs``, bounded by ``bounds``."""
        state = self._prepare(float("nan"))
        data = (self.model, state.data, self.geometry_model, state.distance_data)
        offsets = self.allowance_m[pairs]
        return closest_pairs(
            *data, batch, bounds, pairs, offsets_m=offsets, exact=self._exact, exact_below_m=exact_below_m
        )

    def _coal(self, tier: int, batch: FloatArray) -> NDArray[np.bool_]:
        """Coal's test of ``tier``'s pairs (0 near, 1 far) at ``batch``: the hulls flag, the meshes decide."""
        state = self._coal_state
        flagged = pool_collisions(
            state.pools[tier], self.model, state.data, self.geometry_model, batch, self.num_threads
        )
        if self._exact is None:
            return flagged
        active = np.flatnonzero(self._near if tier == 0 else state.far_on)
        data = (self.model, state.data, self.geometry_model, state.distance_data)
        return self._exact.recheck(flagged, *data, batch, active, state.pair_margins)

    def _prepare(self, margin_m: float) -> _CoalState:
        """Build the two pools and distance data once; set their margin and pairs when the margin changes.

        A NaN ``margin_m`` leaves the margin as it is. The state is the one its copies share
        (:meth:`on_hulls`): what the pools are set to is known to every test that uses them.
        """
        state = self._coal_state
        if not state.pools:
            state.data = self.model.createData()
            state.distance_data = self.geometry_model.createData()
            pools = (pin.GeometryPool(self.model, self.geometry_model, self.num_threads) for _ in range(2))
            state.pools = list(pools)
        if margin_m != state.margin_m and not np.isnan(margin_m):
            state.pair_margins = np.maximum(margin_m - self.allowance_m, 0.0)
            margins = state.pair_margins if self.allowance_m.any() else margin_m
            for pool, active in zip(state.pools, (self._near, state.far_on), strict=True):
                configure_pool(pool, self.geometry_model, margins, active)
                for gdata in pool.getGeometryDatas():
                    for request in gdata.collisionRequests:
                        request.enable_contact = False
            state.margin_m = margin_m
        return state


@dataclass
class _CoalState:
    """coal's pools and data of a screened self test and what they are set to, shared by its copies.

    Attributes:
        far_on: ``(P,)`` the far pool's active pairs.
        pair_margins: ``(P,)`` each pair's coal margin [m]: the margin less its allowance.
        pools: the near pairs' ``GeometryPool`` and the far pairs' (built on the first query).
        data: the model's data of single queries; distance_data: the geometry data of distances.
        margin_m: the margin [m] the pools test (NaN: none yet).
    """

    far_on: BoolArray
    pair_margins: FloatArray
    pools: list[Any] = field(default_factory=list)
    data: Any = None
    distance_data: Any = None
    margin_m: float = float("nan")
