"""A robot against itself: which pairs of its links are checked, and their distances by coal.

The pairs checked are those of collision geometries on links that are not adjacent, minus
the link pairs an SRDF disables (:mod:`cpr_kin.collision.srdf_pairs`) and minus the pairs a
scene allows. A robot with no such pair (the CPR: its SRDF disables all) costs nothing.

The self-clearance required is its own, ``self_margin_m`` (a safety margin against
obstacles is not one a robot can keep from itself: its links pass centimetres apart).
Between two configurations a pair's distance changes only by the joints that carry one of
its links and not the other (:attr:`SelfCollision.pair_radii`), which the certified check of
a curve counts (:mod:`cpr_kin.certified.self_curve`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.bounds.reach import GeometryReach, relative_radii
from cpr_kin.common.errors import CprKinError
from cpr_kin.shapes.exact_pairs import ExactPairs

if TYPE_CHECKING:  # the screen's machinery is imported for a robot with pairs only (_screened)
    from cpr_kin.collision.self_screen import ScreenedSelfTest
    from cpr_kin.collision.self_split import SelfScreen
    from cpr_kin.shapes.exact_meshes import ExactMesh

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class SelfCollision:
    """Distances between a robot's own geometry pairs, for one configuration or a batch.

    Args:
        model: the robot's Pinocchio model.
        collision_model: its collision geometry model (copied, never modified).
        pairs: geometry index pairs to check (:func:`~cpr_kin.collision.srdf_pairs.self_pairs`).
        names: the geometries' names, by index.
        num_threads: threads of :meth:`violated`'s batches.
        reach: each geometry's bounds (:func:`cpr_kin.bounds.reach.geometry_reach`, within the
            robot's joint ranges); by default from the model's position limits.
        allowance_m: ``(P,)`` added to each pair's coal distance [m] wherever a distance,
            bound or margin is asked (:attr:`allowance_m`); default none.
        screen: the pairs' near/far split and bounds (:class:`~cpr_kin.collision.self_split.SelfScreen`);
            by default built on the first query.
        exact_meshes: the robot's exact link meshes by geometry index
            (:attr:`cpr_kin.Robot.exact_meshes`): where a hull comes within a margin, the mesh
            decides (:mod:`cpr_kin.shapes.exact_pairs`). Default: none.
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        pairs: tuple[tuple[int, int], ...],
        names: list[str],
        num_threads: int = 1,
        reach: Sequence[GeometryReach] | None = None,
        allowance_m: FloatArray | None = None,
        screen: SelfScreen | None = None,
        exact_meshes: Mapping[int, ExactMesh] | None = None,
    ) -> None:
        self.model = model
        self.geometry_model = collision_model.copy()
        for a, b in pairs:
            self.geometry_model.addCollisionPair(pin.CollisionPair(a, b))
        self.pair_radii = relative_radii(model, collision_model, pairs, reach)
        """``(P, nj)`` per pair, how fast its distance may change per joint speed [m/rad, m/m]
        (:func:`cpr_kin.bounds.reach.relative_radii`)."""
        self.allowance_m = (
            np.zeros(len(pairs)) if allowance_m is None else np.asarray(allowance_m, dtype=float)
        )
        """``(P,)`` what each pair's distance counts beyond coal's [m]: a world's self margin for a
        pair it holds to contact only (:mod:`cpr_kin.bounds.close_pairs`), else 0. Every distance,
        bound and margin of this class is of coal's distance plus it."""
        if self.allowance_m.shape != (len(pairs),) or not np.all(self.allowance_m >= 0.0):
            raise CprKinError(f"allowance_m must be {len(pairs)} distances >= 0 [m], one per pair")
        self._pairs = pairs
        self._names = names
        self.num_threads = num_threads
        self._screen = screen
        measured = None
        if exact_meshes:  # what the meshes' tests measure answers the later ones near it
            from cpr_kin.collision.clear_balls import ClearBalls

            measured = ClearBalls(self.pair_radii)
        self._exact = ExactPairs(self.geometry_model, exact_meshes or {}, measured)
        self._test: ScreenedSelfTest | None = None  # built on the first query

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        """``(geometry, geometry)`` of every pair, in query order."""
        return tuple((self._names[a], self._names[b]) for a, b in self._pairs)

    def __bool__(self) -> bool:
        return bool(self._pairs)

    def distances(self, q: ArrayLike) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair, ``(N,)`` each, at configurations ``q`` ``(N, nq)``.

        A pair's distance is coal's plus its :attr:`allowance_m`; ``inf`` and ``-1`` when there
        is no pair.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs:
            return np.full(len(batch), np.inf), np.full(len(batch), -1, dtype=np.int64)
        return self._screened().distances(batch)

    def pair_distances(self, q: FloatArray, pair: int, exact_below_m: float = np.inf) -> FloatArray:
        """``(N,)`` coal's distance [m] of pair ``pair`` (index in :attr:`pairs`) at ``q`` ``(N, nq)``.

        Measured on the exact meshes (:mod:`cpr_kin.shapes.exact_pairs`) where the hulls' distance is
        below ``exact_below_m`` [m]; above it, the hulls' (a lower bound).
        """
        return self._screened().pair_distances(np.atleast_2d(np.asarray(q, dtype=float)), pair, exact_below_m)

    def bounds(self, q: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of every pair's distance at ``q`` ``(N, nq)`` (:meth:`pair_bounds`)."""
        return self._screened().bounds(np.atleast_2d(np.asarray(q, dtype=float)))

    def pair_bounds(self, q: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` lower bounds [m] of pair ``pair``'s distance at configurations ``q`` ``(N, nq)``, cheaply.

        Its capsules' distance (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`), at most coal's
        plus coal's error (:func:`~cpr_kin.collision.decisive.coal_error_m`).
        """
        return self._screened().pair_bounds(np.atleast_2d(np.asarray(q, dtype=float)), pair)

    def violated(self, q: ArrayLike, margin_m: float, ordered: bool = False) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``q``.

        coal's collision test with ``margin_m`` as its security margin, which stops at the first
        pair closer than that, in parallel over :attr:`num_threads` threads, screened by the
        pairs' cheap bounds (:class:`~cpr_kin.collision.self_screen.ScreenedSelfTest`): a fraction of
        :meth:`distances`' cost, with the same answer. With ``ordered``, the answer is exact up
        to the first violated configuration, and those after it are reported violated: what an
        edge check needs, without the exact meshes' tests of the configurations past it.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs or not len(batch):
            return np.zeros(len(batch), dtype=bool)
        return self._screened().violated(batch, margin_m, ordered)

    def on_hulls(self) -> SelfCollision:
        """The pairs with the hulls deciding alone (:meth:`cpr_kin.CollisionWorld.on_hulls`)."""
        hulls = copy.copy(self)
        hulls._exact = ExactPairs(self.geometry_model, {})
        if self._pairs:
            hulls._test = self._screened().on_hulls()
        return hulls

    def _screened(self) -> ScreenedSelfTest:
        """The screened coal queries of the pairs, built on first use."""
        if self._test is None:
            from cpr_kin.collision.self_screen import ScreenedSelfTest

            self._test = ScreenedSelfTest(
                self.model,
                self.geometry_model,
                self._pairs,
                self.num_threads,
                self.allowance_m,
                self._screen,
                self._exact,
            )
        return self._test
