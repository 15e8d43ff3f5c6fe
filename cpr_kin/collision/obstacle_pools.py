"""coal's yes/no margin test against one obstacle at a time, in parallel over configurations.

Where a configuration's pair bounds (:mod:`cpr_kin.bounds.pair_bounds`) leave some pair uncertain,
coal decides. Asking it about every pair of the world there made it test a hundred pairs
or more on an arm among shelf boards, although the uncertain ones lie by one or two boards:
most of coal's time went to pairs the bounds had already cleared. So each obstacle has its
own Pinocchio ``GeometryPool`` with only its pairs active, built the first time a
configuration is uncertain about it, and a configuration goes only to the pools of the
obstacles its bounds are uncertain about. The answer is the same: a pair of another
obstacle is certainly farther than the margin. Where a pool's pairs include a link whose exact
mesh decides (:mod:`cpr_kin.shapes.exact_pairs`), the configurations its hull test flags are decided
again with the meshes.
"""

from __future__ import annotations

import copy
import os
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.shapes.exact_pairs import ExactPairs, collide_margin_m

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


def default_threads() -> int:
    """Threads of a world's parallel checks when none are asked for: 2 on 3 cores or more, else 1.

    The cores are those this process may run on. coal's parallel batches (Pinocchio's OpenMP
    loops) end with their threads waiting for one another. Where every core is busy, a batch's
    second thread waits for the scheduler: a time slice of milliseconds, for a batch whose work is
    microseconds. On 2 cores a second thread pays only while nothing else runs, so it is left
    out there (docs/tuning.md, Threads).
    """
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return 2 if cores >= 3 else 1


def pool_collisions(
    pool: Any, model: Any, data: Any, geometry_model: Any, batch: FloatArray, num_threads: int
) -> BoolArray:
    """``(N,)`` coal's yes/no test of ``pool``'s active pairs at ``batch``, each stopping at its first hit.

    In parallel over ``num_threads`` threads; one configuration (a sampling planner's query)
    serially in ``data`` and the pool's first geometry data, where the threads would cost
    more than the test.
    """
    if len(batch) == 1:
        gdata = pool.getGeometryData(0)
        return np.array([pin.computeCollisions(model, data, geometry_model, gdata, batch[0], True)])
    found = pin.computeCollisionsInParallel(num_threads, pool, np.asfortranarray(batch.T), True)
    return np.asarray(found, dtype=bool)


class ObstaclePools:
    """One ``GeometryPool`` per obstacle, its pairs within reach of the margin active.

    Args:
        model: the robot's Pinocchio model.
        geometry_model: the world's geometry model (robot and obstacles, every pair added).
        pair_obstacle: ``(P,)`` the obstacle of each of its collision pairs.
        num_threads: threads of coal's batches.
        exact: the pairs on the robot's exact meshes (default: none decides).
    """

    def __init__(
        self,
        model: Any,
        geometry_model: Any,
        pair_obstacle: IntArray,
        num_threads: int,
        exact: ExactPairs | None = None,
    ) -> None:
        self.model, self.geometry_model, self.num_threads = model, geometry_model, num_threads
        self._pair_obstacle = pair_obstacle
        self._exact = exact if exact else None
        self._data = model.createData()
        self._exact_data: Any = None
        self._pools: dict[int, Any] = {}
        self._margin_m: dict[int, float] = {}

    def on_hulls(self) -> ObstaclePools:
        """The pools with the hulls deciding alone (:meth:`cpr_kin.CollisionWorld.on_hulls`)."""
        hulls = copy.copy(self)
        hulls._exact = None
        return hulls

    def violated(
        self,
        batch: FloatArray,
        uncertain: BoolArray,
        margin_m: float,
        near: BoolArray,
        ordered: bool = False,
    ) -> BoolArray:
        """``(N,)`` whether some pair is closer than ``margin_m`` [m] at configurations ``batch``.

        Args:
            batch: ``(N, nq)`` configurations.
            uncertain: ``(N, O)`` the obstacles coal must test at each (the others are
                certainly farther than the margin).
            margin_m: the security margin [m].
            near: ``(P,)`` the pairs that may come within the margin (the others are not tested).
            ordered: decide the configurations in order, one at a time, up to the first
                violated one; those after it are reported violated without a test.
        """
        violated = np.zeros(len(batch), dtype=bool)
        if len(batch) == 1:  # one configuration: the obstacles in turn, without the array work
            violated[0] = self._one_violated(batch, np.flatnonzero(uncertain[0]).tolist(), margin_m, near)
            return violated
        if ordered:  # one at a time, up to the first violated (row by row, each row's obstacles in turn)
            for row, obstacle in zip(*(index.tolist() for index in np.nonzero(uncertain)), strict=True):
                if self._one_violated(batch[row : row + 1], [obstacle], margin_m, near):
                    violated[row:] = True
                    break
            return violated
        for obstacle in np.flatnonzero(uncertain.any(axis=0)).tolist():
            rows = np.flatnonzero(uncertain[:, obstacle] & ~violated)
            if rows.size:
                violated[rows] = self._tested(obstacle, batch[rows], margin_m, near, self.num_threads)
        return violated

    def _one_violated(self, one: FloatArray, obstacles: list[int], margin_m: float, near: BoolArray) -> bool:
        """Whether the configuration ``one`` ``(1, nq)`` violates the margin of one of ``obstacles``."""
        return any(self._tested(obstacle, one, margin_m, near, 1)[0] for obstacle in obstacles)

    def _tested(
        self, obstacle: int, batch: FloatArray, margin_m: float, near: BoolArray, num_threads: int
    ) -> BoolArray:
        """``(N,)`` coal's test of ``obstacle``'s pairs at ``batch``: the hulls flag, the meshes decide."""
        pool = self._prepared(obstacle, margin_m, near)
        flagged = pool_collisions(pool, self.model, self._data, self.geometry_model, batch, num_threads)
        if self._exact is None:
            return flagged
        if self._exact_data is None:
            self._exact_data = self.geometry_model.createData()
        active = np.flatnonzero(near & (self._pair_obstacle == obstacle))
        margins = np.full(len(self._pair_obstacle), margin_m)
        data = (self.model, self._data, self.geometry_model, self._exact_data)
        return self._exact.recheck(flagged, *data, batch, active, margins)

    def _prepared(self, obstacle: int, margin_m: float, near: BoolArray) -> Any:
        """The obstacle's pool, built once, its margin and active pairs set when the margin changes."""
        if obstacle not in self._pools:
            self._pools[obstacle] = pin.GeometryPool(self.model, self.geometry_model, self.num_threads)
        pool = self._pools[obstacle]
        if self._margin_m.get(obstacle) != margin_m:
            configure_pool(pool, self.geometry_model, margin_m, near & (self._pair_obstacle == obstacle))
            self._margin_m[obstacle] = margin_m
        return pool


def configure_pool(pool: Any, geometry_model: Any, margin_m: float | FloatArray, active: BoolArray) -> None:
    """Give each geometry data of ``pool`` the security margin ``margin_m`` [m], only ``active`` pairs on.

    ``margin_m`` is one margin for every pair, or one per collision pair of ``geometry_model``;
    coal is asked at least :data:`~cpr_kin.shapes.exact_pairs.COLLIDE_MARGIN_AT_LEAST_M`.
    """
    if np.ndim(margin_m) == 0:
        margins = np.full((geometry_model.ngeoms,) * 2, float(margin_m))
    else:
        margins = np.zeros((geometry_model.ngeoms,) * 2)
        for pair, margin in zip(
            geometry_model.collisionPairs, np.asarray(margin_m, dtype=float), strict=True
        ):
            margins[pair.first, pair.second] = margins[pair.second, pair.first] = margin
    margins = collide_margin_m(margins)
    for gdata in pool.getGeometryDatas():
        gdata.setSecurityMargins(geometry_model, margins, True, True)
        for p, on in enumerate(active):
            (gdata.activateCollisionPair if on else gdata.deactivateCollisionPair)(p)
