"""The distance between two line segments, compiled (the core of every capsule bound)."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]


@njit
def segment_distance(p: FloatArray, q: FloatArray) -> float:
    """Distance [m] between the segments ``p`` and ``q``, each ``(2, 3)`` end points.

    The closest points of two segments (Ericson, *Real-Time Collision Detection*, 5.1.9):
    the infinite lines' parameters clamped to ``[0, 1]`` in turn, degenerate segments
    (points) and parallel ones included. Scalar arithmetic: no array is allocated.
    """
    d1x, d1y, d1z = p[1, 0] - p[0, 0], p[1, 1] - p[0, 1], p[1, 2] - p[0, 2]
    d2x, d2y, d2z = q[1, 0] - q[0, 0], q[1, 1] - q[0, 1], q[1, 2] - q[0, 2]
    rx, ry, rz = p[0, 0] - q[0, 0], p[0, 1] - q[0, 1], p[0, 2] - q[0, 2]
    a = d1x * d1x + d1y * d1y + d1z * d1z
    e = d2x * d2x + d2y * d2y + d2z * d2z
    f = d2x * rx + d2y * ry + d2z * rz
    tiny = 1e-18
    if a <= tiny and e <= tiny:
        s = t = 0.0
    elif a <= tiny:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = d1x * rx + d1y * ry + d1z * rz
        if e <= tiny:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = d1x * d2x + d1y * d2y + d1z * d2z
            denominator = a * e - b * b
            s = min(max((b * f - c * e) / denominator, 0.0), 1.0) if denominator > tiny else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = min(max(-c / a, 0.0), 1.0), 0.0
            elif t > 1.0:
                s, t = min(max((b - c) / a, 0.0), 1.0), 1.0
    x = rx + s * d1x - t * d2x
    y = ry + s * d1y - t * d2y
    z = rz + s * d1z - t * d2z
    return float(np.sqrt(x * x + y * y + z * z))
