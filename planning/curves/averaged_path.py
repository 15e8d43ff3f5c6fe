"""Where the fastest timing's moving averages take a sampled path: the cut of its bends, foreseen.

:func:`~planning.curves.path_timing.time_path` runs each joint's motion along the phase-plane
profile through two moving averages in time, of widths ``w`` and ``r w``: together one
average whose kernel is a trapezoid (the convolution of the two boxes) of base ``(1 + r) w``.
The averages of nearby points of a curve lie inside its bends, so the timed trajectory cuts
them, by ``w^2 (1 + r^2) / 24`` times the joints' acceleration where the profile turns
(the kernel's variance over two), up to a centimetre on an arm that retracts and swings
between pillars. A path that keeps the fitness's clearance only just may then come inside
the margin, and its fastest timing fails the certified check after it has cost a timing and
a verification.

:func:`averaged_samples` computes, for a path known at a few dozen samples, the profile the
duration estimate computes (:mod:`planning.curves.jerk_window`: the same phase plane, and the
window widened at most the rounds the caller asks: the choice's foresight asks none, as the
timing mostly keeps the narrow window, :mod:`planning.curves.local_caps`), the instants at
which it reaches each sample, and each sample's position averaged over the kernel about its
instant (a midpoint rule of :data:`QUADRATURE` points on the path interpolated linearly in
time). The choice stage (:mod:`planning.pipeline.choose`) times first the candidates whose
averaged samples keep the clearance. Not modelled: the timing's velocity caps and locally
lowered accelerations, which slow the profile where they bind and so cut less; the
prediction errs towards a cut.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from planning.curves.jerk_window import profile_window
from planning.curves.phase_plane import kept_derivatives, kept_samples, phase_plane_profile

FloatArray = NDArray[np.float64]

QUADRATURE = 16
"""Points of the midpoint rule over the averages' trapezoid kernel."""


@njit
def trapezoid_kernel(window_s: float, second_share: float, points: int) -> tuple[FloatArray, FloatArray]:
    """Offsets [s] and weights (summing to 1) of the midpoint rule over the two boxes' kernel.

    The convolution of boxes of widths ``w = window_s`` and ``r w``: height ``1 / w`` within
    ``(1 - r) w / 2`` of its centre, falling linearly to 0 at ``(1 + r) w / 2``.
    """
    wide, narrow = window_s, second_share * window_s
    half, flat = 0.5 * (wide + narrow), 0.5 * (wide - narrow)
    spacing = 2.0 * half / points
    offsets, weights = np.empty(points), np.empty(points)
    for q in range(points):
        tau = -half + (q + 0.5) * spacing
        height = 1.0 / wide if abs(tau) <= flat else (half - abs(tau)) / (wide * narrow)
        offsets[q], weights[q] = tau, height * spacing
    return offsets, weights / weights.sum()


@njit
def averaged_samples(
    points: FloatArray, limits: FloatArray, window_s: float, rounds: int, tolerance: float, share: float
) -> FloatArray:
    """``(S, M, nj)`` the samples of ``S`` paths ``(S, M, nj)`` where the timing's averages take them.

    Each path's profile under the velocity and acceleration limits ``limits[0]``,
    ``limits[1]`` and its window for the jerk limits ``limits[2]`` (from ``window_s``,
    widened at most ``rounds`` times while the jerk exceeds ``1 + tolerance`` of its
    limit; ``share``: the second average's width as a share of the first's) are the
    duration estimate's (:func:`~planning.curves.jerk_window.sampled_path_durations`); each sample is averaged
    over the kernel of :func:`trapezoid_kernel` about the instant the profile reaches it
    (before the start and after the end the path rests at its ends). A sample the profile
    drops (closer than ``1e-9`` to the one before) takes its predecessor's displacement. A
    path too short for a profile is returned as it is.
    """
    averaged = points.copy()
    for s in range(points.shape[0]):
        index = kept_samples(points[s], limits[0])
        steps, d1, d2 = kept_derivatives(points[s], index, limits[0])
        if index.size < 2 or len(d1) < 2:
            continue
        kept = points[s][index]
        x = phase_plane_profile(d1, d2, steps, limits[0], limits[1], np.zeros_like(d1))
        times, window, _ = profile_window(x, steps, d1, limits[2], window_s, rounds, tolerance, share)
        offsets, weights = trapezoid_kernel(window, share, QUADRATURE)
        moved = _averaged(kept, times, offsets, weights)
        g = 0
        for i in range(points.shape[1]):  # back onto every sample
            while g + 1 < index.size and index[g + 1] <= i:
                g += 1
            averaged[s, i] = points[s, i] + moved[g] - kept[g]
    return averaged


@njit
def _averaged(kept: FloatArray, times: FloatArray, offsets: FloatArray, weights: FloatArray) -> FloatArray:
    """``(m, nj)`` the path ``kept`` (reached at ``times``, linear between) averaged about each instant."""
    m, joints = kept.shape
    result = np.zeros((m, joints))
    for q in range(offsets.size):
        k = 0
        for g in range(m):
            t = times[g] + offsets[q]
            if t <= times[0]:
                point_k, point_next, share = 0, 0, 0.0
            elif t >= times[m - 1]:
                point_k, point_next, share = m - 1, m - 1, 0.0
            else:
                while times[k + 1] < t:
                    k += 1
                point_k, point_next = k, k + 1
                share = (t - times[k]) / max(times[k + 1] - times[k], 1e-300)
            for joint in range(joints):
                here = kept[point_k, joint]
                result[g, joint] += weights[q] * (here + share * (kept[point_next, joint] - here))
    return result
