"""The closest of many geometry pairs by coal, visiting the pairs in the order of their lower bounds.

Where a configuration violates a margin, the planner asks how deep: the smallest distance
over every pair. Pinocchio's ``computeDistances`` runs coal on every active pair, a hundred
or more on an arm among shelves, although only a few come near. Given a lower bound of each
pair's distance (:mod:`cpr_kin.bounds.pair_bounds`, :mod:`cpr_kin.bounds.self_bounds`), the pairs are
visited from the smallest bound up and the visit stops at the first pair whose bound is no
smaller than the smallest distance found: no pair left can be closer (a bound counts only
when positive: overlapping shapes may penetrate any depth). The answer is coal's
distance of the closest pair, as with every pair computed; only the pairs that may be
closest cost a query.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.collision.decisive import below_coal
from cpr_kin.shapes.exact_pairs import ExactPairs

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def closest_pairs(
    model: Any,
    data: Any,
    geometry_model: Any,
    geometry_data: Any,
    batch: FloatArray,
    bounds: FloatArray,
    pair_index: IntArray,
    below_m: float = np.inf,
    offsets_m: FloatArray | None = None,
    exact: ExactPairs | None = None,
    exact_below_m: float = np.inf,
) -> tuple[FloatArray, IntArray]:
    """Smallest coal distance [m] over the pairs at each configuration, and its pair.

    Args:
        model: the robot's Pinocchio model.
        data: its data (the joint placements are written into it).
        geometry_model: the geometry model holding the pairs.
        geometry_data: its data (placements and distance results are written into it).
        batch: ``(N, nq)`` configurations.
        bounds: ``(N, P)`` lower bounds [m] of the pairs' distances at those configurations
            (at most coal's distance plus its error, :func:`~cpr_kin.collision.decisive.coal_error_m`).
        pair_index: ``(P,)`` the pairs' indices in ``geometry_model.collisionPairs``.
        below_m: only distances below this matter [m]: pairs bounded above it are not
            computed, and where the smallest distance is not below it, ``inf`` and ``-1``
            are returned (a distance below it on a pair's meshes is one on its hulls: the
            depth is the hulls').
        offsets_m: ``(P,)`` added to each pair's coal distance [m] (its bound includes it);
            a pair with a positive offset is always computed.
        exact: the geometry model's pairs on the robot's exact meshes: a pair that may be
            the closest is measured on them where it has one
            (:meth:`cpr_kin.shapes.exact_pairs.ExactPairs.settled`); its distance is no smaller, so the
            bounds still hold.
        exact_below_m: distances at or above this [m] need not be exact: a pair whose meshes
            are that far apart counts as that far (a lower bound).

    Returns:
        The distance and the pair's index in ``geometry_model.collisionPairs`` (``-1``: none
        computed), ``(N,)`` each.
    """
    distance = np.full(len(batch), np.inf)
    closest = np.full(len(batch), -1, dtype=np.int64)
    offsets = np.zeros(bounds.shape[1]) if offsets_m is None else np.asarray(offsets_m, dtype=float)
    if np.any(offsets > 0.0):
        bounds = np.where(offsets > 0.0, -np.inf, bounds)  # an offset bound tells nothing of coal's sign
    order = np.argsort(bounds, axis=1, kind="stable")
    # each pair's bound less the tolerance, certain where positive; where the bounding shapes
    # overlap, coal's signed distance (a penetration depth) may be any negative value: -inf
    certain = below_coal(np.take_along_axis(bounds, order, axis=1))
    certain[certain <= 0.0] = -np.inf
    # each row ascends, and a visit stops below ``below_m``: only a row's first pairs below it are visited
    visited = np.count_nonzero(certain < below_m, axis=1).tolist()
    pairs, extra = pair_index.tolist(), offsets.tolist()
    refined = exact.refined.tolist() if exact else []
    on_meshes = exact.settled if exact else None
    place, compute = pin.updateGeometryPlacements, pin.computeDistance
    for k, count in enumerate(visited):
        if not count:
            continue
        place(model, data, geometry_model, geometry_data, batch[k])
        best, which, limit = np.inf, -1, below_m
        # read element by element: a visit mostly ends after a pair or two of a row of hundreds
        row_bounds, row_order = certain[k], order[k]
        for j in range(count):
            if row_bounds[j] >= limit:
                break  # no pair left can be closer
            column = int(row_order[j])
            pair = pairs[column]
            found = compute(geometry_model, geometry_data, pair).min_distance
            if on_meshes is not None and refined[pair]:
                ceiling = min(limit, exact_below_m) - extra[column]
                if found < ceiling:
                    found = on_meshes(geometry_data, pair, found, ceiling, below_m - extra[column])
            found += extra[column]
            if found < best:
                best, which, limit = found, pair, min(found, below_m)
        if best < below_m:
            distance[k], closest[k] = best, which
    return distance, closest
