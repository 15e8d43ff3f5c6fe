"""The search's duration estimate of sampled paths when the joint torques bind.

The fitness ranks candidates by how fast their paths can be run
(:func:`~planning.curves.jerk_window.sampled_path_durations`). Where the robot's torques
bind (a payload, a fast arm), that estimate must keep them too, or the search prefers paths
that gravity makes slow: :func:`sampled_torque_durations` adds the torques as rows of the
phase plane (:mod:`planning.curves.torque_limits`), from their terms on a few samples of
each path.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from planning.curves.jerk_window import jerk_limited_duration, profile_window, sampled_path_durations
from planning.curves.phase_plane import kept_samples, phase_plane_profile, sampled_derivatives
from planning.curves.torque_limits import HEADROOM, TorqueModel
from planning.curves.velocity_caps import ROUNDS, TOLERANCE

FloatArray = NDArray[np.float64]

TERM_STRIDE = 4
"""Every how many samples of a path :func:`sampled_torque_durations` computes the torques' terms."""


def sampled_torque_durations(
    samples: FloatArray,
    fitted: NDArray[np.intp],
    limits: FloatArray,
    model: TorqueModel,
    window_s: float,
    second_share: float,
) -> FloatArray:
    """``(S,)`` the search's duration estimates [s] of sampled paths ``(S, K, nq)``, torques limited too.

    :func:`~planning.curves.jerk_window.sampled_path_durations` on the ``fitted`` joints
    (``limits`` ``(3, len(fitted))``, the averages' ``window_s`` [s] and ``second_share``)
    with the torques as rows of the phase plane
    (:func:`~planning.curves.torque_limits.phase_plane_rows`). Their terms are computed on
    every :data:`TERM_STRIDE`-th sample and the last, and interpolated between (they vary
    smoothly along a path); a path where gravity alone exceeds a limit keeps the estimate
    without torques (the verification will refuse it, naming the torque).
    """
    limited = np.isfinite(model.effort)
    bound = model.effort[limited] * (1.0 - HEADROOM)
    points = np.ascontiguousarray(samples[:, :, fitted])
    velocity, acceleration, jerk = limits
    durations = np.zeros(len(samples))
    paths, rows_q, rows_dq, rows_ddq = [], [], [], []
    for s in range(len(samples)):  # each path's samples kept, derivatives and picked rows
        index = kept_samples(points[s], velocity)
        if len(index) < 2:
            continue
        steps, d1, d2 = sampled_derivatives(points[s], velocity)
        pick = np.arange(0, len(index), TERM_STRIDE)  # and the last sample
        pick = pick if pick[-1] == len(index) - 1 else np.append(pick, len(index) - 1)
        dq, ddq = np.zeros((2, len(pick), samples.shape[2]))
        dq[:, fitted], ddq[:, fitted] = d1[pick], d2[pick]
        paths.append((s, steps, d1, d2, pick))
        rows_q.append(samples[s, index[pick]])
        rows_dq.append(dq)
        rows_ddq.append(ddq)
    if not paths:
        return durations
    # one batched RNEA for every path's picked rows
    every = np.stack(
        model.path_terms(np.concatenate(rows_q), np.concatenate(rows_dq), np.concatenate(rows_ddq))
    )
    ends = np.cumsum([len(pick) for *_, pick in paths])
    for (s, steps, d1, d2, pick), end in zip(paths, ends, strict=True):
        terms = np.ascontiguousarray(every[:, end - len(pick) : end][:, :, limited])
        if np.any(np.abs(terms[2]) > bound):  # gravity beyond a limit: the estimate without torques
            plain = sampled_path_durations(
                points[s : s + 1], velocity, acceleration, jerk, window_s, ROUNDS, TOLERANCE, second_share
            )
            durations[s] = plain[0]
            continue
        durations[s] = torque_limited_duration(
            steps, d1, d2, pick, terms, bound, limits, window_s, ROUNDS, TOLERANCE, second_share
        )
    return durations


@njit
def torque_limited_duration(
    steps: FloatArray,
    d1: FloatArray,
    d2: FloatArray,
    pick: NDArray[np.int64],
    terms: FloatArray,
    bound: FloatArray,
    limits: FloatArray,
    window_s: float,
    rounds: int,
    tolerance: float,
    second_share: float,
) -> float:
    """The duration estimate [s] of one sampled path with its torques as rows of the phase plane.

    The path's arc-length steps ``steps`` and derivatives ``d1``, ``d2`` ``(M, nj)``
    (:func:`~planning.curves.phase_plane.sampled_derivatives`); the torques' ``terms``
    ``(3, P, L)`` (slope, curve, gravity's offset) at its samples ``pick`` ``(P,)``,
    interpolated linearly between them, each within ``bound`` ``(L,)``; ``limits`` ``(3, nj)``
    velocity, acceleration and jerk. The rows of
    :func:`~planning.curves.torque_limits.phase_plane_rows`, compiled with the interpolation,
    the profile, its jerk window and duration: the per-path work of
    :func:`sampled_torque_durations` without the Python between them.
    """
    kept, joints = d1.shape
    torques = terms.shape[2]
    rows = joints + torques
    slope, curve, offset = np.zeros((kept, rows)), np.zeros((kept, rows)), np.zeros((kept, rows))
    slope[:, :joints], curve[:, :joints] = d1, d2
    right = 1
    for k in range(kept):
        while right < len(pick) - 1 and pick[right] < k:
            right += 1
        share = (k - pick[right - 1]) / (pick[right] - pick[right - 1])
        for r in range(torques):
            slope[k, joints + r] = terms[0, right - 1, r] * (1.0 - share) + terms[0, right, r] * share
            curve[k, joints + r] = terms[1, right - 1, r] * (1.0 - share) + terms[1, right, r] * share
            offset[k, joints + r] = terms[2, right - 1, r] * (1.0 - share) + terms[2, right, r] * share
    velocity = np.full(rows, np.inf)
    velocity[:joints] = limits[0]
    acceleration = np.empty(rows)
    acceleration[:joints], acceleration[joints:] = limits[1], bound
    x = phase_plane_profile(slope, curve, steps, velocity, acceleration, offset)
    times, window, usage = profile_window(x, steps, d1, limits[2], window_s, rounds, tolerance, second_share)
    return jerk_limited_duration(times, window, usage, second_share)
