"""The exact distance from a line segment to a box, compiled: the box bound of the pair bounds.

A box obstacle (and any shape bounded by its box) is bounded by the distance from a robot
capsule's segment to the box (:mod:`cpr_kin.bounds.bound_kernels`); why it is worth being exact:
``docs/tuning.md``, Kernels.
"""

from __future__ import annotations

import numpy as np

from cpr_kin.common.compiled import njit


@njit
def excess(p: float, half: float) -> float:
    """How far the coordinate ``p`` lies beyond the slab ``|p| <= half``, signed (0 within it)."""
    if p > half:
        return p - half
    if p < -half:
        return p + half
    return 0.0


@njit
def _box_slope(
    t: float,
    ax: float,
    ay: float,
    az: float,
    dx: float,
    dy: float,
    dz: float,
    hx: float,
    hy: float,
    hz: float,
) -> float:
    """Half the derivative in ``t`` of the squared distance from ``a + t d`` to the box, half sides ``h``."""
    return dx * excess(ax + t * dx, hx) + dy * excess(ay + t * dy, hy) + dz * excess(az + t * dz, hz)


@njit
def segment_box_distance(
    ax: float, ay: float, az: float, dx: float, dy: float, dz: float, hx: float, hy: float, hz: float
) -> float:
    """The distance [m] from the segment ``a -> a + d`` to the box ``|x| <= hx, |y| <= hy, |z| <= hz``.

    The squared distance from the point ``a + t d`` is ``f(t) = sum_i e_i(t)^2`` with ``e_i``
    the coordinate's excess beyond the box's slab: convex in ``t``, its derivative continuous,
    nondecreasing and linear between the kinks where a coordinate crosses a face's plane
    (``t = (+-h_i - a_i) / d_i``). The minimum over ``[0, 1]`` lies at an end where the
    derivative does not change sign there, else between the two kinks (or ends) that bracket
    the sign change, where the derivative is linear and its zero is interpolated. Exact up to
    rounding (1e-16 m at the scale of a robot); why a box is worth it: ``docs/tuning.md``, Kernels.
    """
    low, high = 0.0, 1.0
    slope_low = _box_slope(low, ax, ay, az, dx, dy, dz, hx, hy, hz)
    slope_high = _box_slope(high, ax, ay, az, dx, dy, dz, hx, hy, hz)
    if slope_low >= 0.0:
        t = low
    elif slope_high <= 0.0:
        t = high
    else:
        t = -1.0
        for axis in range(3):
            start = ax if axis == 0 else (ay if axis == 1 else az)
            step = dx if axis == 0 else (dy if axis == 1 else dz)
            half = hx if axis == 0 else (hy if axis == 1 else hz)
            if step == 0.0:
                continue
            for side in (-1.0, 1.0):
                kink = (side * half - start) / step
                if low < kink < high:
                    slope = _box_slope(kink, ax, ay, az, dx, dy, dz, hx, hy, hz)
                    if slope < 0.0:
                        low, slope_low = kink, slope
                    elif slope > 0.0:
                        high, slope_high = kink, slope
                    else:
                        t = kink
        if t < 0.0:  # the derivative is linear on [low, high]: its zero
            t = low - slope_low * (high - low) / (slope_high - slope_low)
    ex, ey, ez = excess(ax + t * dx, hx), excess(ay + t * dy, hy), excess(az + t * dz, hz)
    return float(np.sqrt(ex * ex + ey * ey + ez * ez))
