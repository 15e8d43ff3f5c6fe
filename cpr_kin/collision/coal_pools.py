"""coal's yes/no margin test of many configurations at once, in Pinocchio's ``GeometryPool``.

A pool holds a geometry data per thread, each with the pairs it tests active and their
security margins set (:func:`configure_pool`); :func:`pool_collisions` tests a batch of
configurations on it, in parallel over :func:`default_threads` threads. The robot's own pairs
use it (:mod:`cpr_kin.collision.self_screen`, :mod:`cpr_kin.collision.near_cells`).
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.shapes.coal_queries import collide_margin_m

FloatArray = NDArray[np.float64]
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


def configure_pool(pool: Any, geometry_model: Any, margin_m: float | FloatArray, active: BoolArray) -> None:
    """Give each geometry data of ``pool`` the security margin ``margin_m`` [m], only ``active`` pairs on.

    ``margin_m`` as :func:`set_margins` takes it.
    """
    for gdata in pool.getGeometryDatas():
        set_margins(gdata, geometry_model, margin_m)
        for p, on in enumerate(active):
            (gdata.activateCollisionPair if on else gdata.deactivateCollisionPair)(p)


def set_margins(geometry_data: Any, geometry_model: Any, margin_m: float | FloatArray) -> None:
    """Give ``geometry_data``'s collision tests the security margin ``margin_m`` [m].

    ``margin_m`` is one margin for every pair, or one per collision pair of ``geometry_model``;
    coal is asked at least :data:`~cpr_kin.shapes.coal_queries.COLLIDE_MARGIN_AT_LEAST_M`.
    """
    if np.ndim(margin_m) == 0:
        margins = np.full((geometry_model.ngeoms,) * 2, float(margin_m))
    else:
        margins = np.zeros((geometry_model.ngeoms,) * 2)
        for pair, margin in zip(
            geometry_model.collisionPairs, np.asarray(margin_m, dtype=float), strict=True
        ):
            margins[pair.first, pair.second] = margins[pair.second, pair.first] = margin
    geometry_data.setSecurityMargins(geometry_model, collide_margin_m(margins), True, True)
