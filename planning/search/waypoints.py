"""Waypoints along a sampled path, for a spline through them to follow it.

A sampling planner's path has a few corners; the waypoint search's spline passes through a
fixed number of waypoints. Two placements follow the path: the corners kept and the rest
where the path is longest (:func:`waypoints_along`), or all evenly spaced in arc length
(:func:`evenly_along`). The spline through either may cut or overshoot the path where the
other does not (the corners' placement keeps its turns; the even one keeps the spline's
segments alike, as its uniform knots assume), so the seeding offers placements between
them too (:func:`placements_along`) and keeps the best.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def waypoints_along(path: FloatArray, count: int, weights: FloatArray) -> FloatArray:
    """``(count, d)`` interior waypoints for a spline that follows ``path`` (its vertices kept).

    The path's interior vertices are its corners and are kept when there are at most
    ``count``; the rest are placed on the longest pieces (each split evenly), so that
    the spline through start, waypoints and goal stays near the path. With more corners
    than ``count``, points evenly spaced in arc length (:func:`evenly_along`).
    """
    corners = path[1:-1]
    if len(corners) > count:
        return evenly_along(path, count, weights)
    pieces = len(path) - 1
    splits = np.ones(pieces, dtype=np.intp)  # parts per piece
    lengths = np.abs(np.diff(path, axis=0)) @ weights
    for _ in range(count - len(corners)):
        splits[int(np.argmax(lengths / splits))] += 1
    points: list[FloatArray] = []
    for k in range(pieces):
        points.extend(path[k] + (m / splits[k]) * (path[k + 1] - path[k]) for m in range(1, splits[k]))
        if k + 1 < pieces:
            points.append(path[k + 1])
    return np.array(points)


def evenly_along(path: FloatArray, count: int, weights: FloatArray) -> FloatArray:
    """``(count, d)`` points evenly spaced along ``path`` in arc length (``weights`` per joint)."""
    lengths = np.abs(np.diff(path, axis=0)) @ weights
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    at = arc[-1] * np.arange(1, count + 1) / (count + 1)
    return np.array([np.interp(at, arc, path[:, j]) for j in range(path.shape[1])]).T


def placements_along(
    path: FloatArray, count: int, weights: FloatArray, shares: Sequence[float]
) -> FloatArray:
    """``(len(shares), count, d)`` waypoint placements along ``path``, one per share.

    Share 0 is :func:`waypoints_along` (the corners kept), 1 :func:`evenly_along`; a share
    between moves each waypoint that far from the first placement towards the second.
    """
    corners, even = waypoints_along(path, count, weights), evenly_along(path, count, weights)
    return np.array([(1.0 - share) * corners + share * even for share in shares])
