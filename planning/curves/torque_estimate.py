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
from planning.curves.jerk_window import jerk_limited_duration, profile_window
from planning.curves.phase_plane import kept_derivatives, kept_samples, phase_plane_profile
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
    without torques (the verification will refuse it, naming the torque). Two compiled
    passes round one batched RNEA of every path's picked samples: :func:`path_rows`, then
    :func:`torque_durations`.
    """
    limited = np.isfinite(model.effort)
    bound = model.effort[limited] * (1.0 - HEADROOM)
    fitted_index = np.asarray(fitted, dtype=np.int64)
    kept, steps, d1, d2, q, dq, ddq = path_rows(np.ascontiguousarray(samples), fitted_index, limits[0])
    if not len(q):
        return np.zeros(len(samples))
    every = np.stack(model.path_terms(q, dq, ddq))
    terms = np.ascontiguousarray(every[:, :, limited])
    averaging = (window_s, ROUNDS, TOLERANCE, second_share)
    return torque_durations((kept, steps, d1, d2), terms, bound, limits, averaging)


@njit
def path_picks(kept: int, stride: int = TERM_STRIDE) -> NDArray[np.int64]:
    """The kept samples whose torque terms are computed: every ``stride``-th and the last."""
    last_taken = (kept - 1) % stride == 0
    pick = np.empty((kept - 1) // stride + 1 + (0 if last_taken else 1), dtype=np.int64)
    for i in range((kept - 1) // stride + 1):
        pick[i] = i * stride
    if not last_taken:
        pick[-1] = kept - 1
    return pick


@njit
def path_rows(
    samples: FloatArray, fitted: NDArray[np.int64], velocity: FloatArray
) -> tuple[NDArray[np.int64], FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """Each path of ``samples`` ``(S, K, nq)``: its kept samples and derivatives, and the rows RNEA needs.

    Returns ``kept`` ``(S,)``, how many samples each path keeps
    (:func:`~planning.curves.phase_plane.kept_samples`; fewer than 2: no motion, no rows);
    ``steps`` ``(S, K)``, their arc-length steps (the first ``kept - 1``); ``d1``, ``d2``
    ``(S, K, nj)``, the ``fitted`` joints' ``dq/ds`` and ``d2q/ds2`` there, in seconds at their
    ``velocity`` limits (:func:`~planning.curves.phase_plane.kept_derivatives`); and ``q``,
    ``dq``, ``ddq`` ``(T, nq)``, the configurations and derivatives (0 for the joints not
    fitted) at :func:`path_picks` (every :data:`TERM_STRIDE`-th kept sample and the last),
    path after path.
    """
    paths, count, nq = samples.shape
    joints = len(fitted)
    kept = np.zeros(paths, dtype=np.int64)
    indices = np.zeros((paths, count), dtype=np.int64)  # the kept samples' indices
    steps = np.zeros((paths, count))
    d1_all, d2_all = np.zeros((paths, count, joints)), np.zeros((paths, count, joints))
    total = 0
    for s in range(paths):
        points = np.ascontiguousarray(samples[s][:, fitted])
        index = kept_samples(points, velocity)
        if len(index) < 2:
            continue
        step, d1, d2 = kept_derivatives(points, index, velocity)
        kept[s], indices[s, : len(index)] = len(index), index
        steps[s, : len(step)], d1_all[s, : len(index)], d2_all[s, : len(index)] = step, d1, d2
        total += len(path_picks(len(index)))
    q, dq, ddq = np.empty((total, nq)), np.zeros((total, nq)), np.zeros((total, nq))
    row = 0
    for s in range(paths):
        if kept[s] < 2:
            continue
        for k in path_picks(kept[s]):
            q[row] = samples[s, indices[s, k]]
            for j in range(joints):
                dq[row, fitted[j]], ddq[row, fitted[j]] = d1_all[s, k, j], d2_all[s, k, j]
            row += 1
    return kept, steps, d1_all, d2_all, q, dq, ddq


@njit
def torque_durations(
    paths: tuple[NDArray[np.int64], FloatArray, FloatArray, FloatArray],
    terms: FloatArray,
    bound: FloatArray,
    limits: FloatArray,
    averaging: tuple[float, int, float, float],
) -> FloatArray:
    """``(S,)`` each path's duration estimate [s], its torques' ``terms`` ``(3, T, L)`` at its rows.

    ``paths``: :func:`path_rows`' ``kept``, ``steps``, ``d1``, ``d2``; ``averaging``: the averages'
    first width [s], the widenings' rounds and tolerance, and the second share. Each path that
    moves gets :func:`torque_limited_duration`; where gravity alone exceeds a ``bound`` ``(L,)``,
    the estimate without torques, as :func:`~planning.curves.jerk_window.sampled_path_durations`
    gives it.
    """
    kept_of, steps_of, d1_of, d2_of = paths
    window_s, rounds, tolerance, second_share = averaging
    durations = np.zeros(len(kept_of))
    velocity, acceleration, jerk = limits[0], limits[1], limits[2]
    start = 0
    for s in range(len(kept_of)):
        kept = kept_of[s]
        if kept < 2:
            continue
        pick = path_picks(kept)
        steps = steps_of[s, : max(kept - 1, 1)].copy()
        d1, d2 = d1_of[s, :kept].copy(), d2_of[s, :kept].copy()
        own = terms[:, start : start + len(pick)]
        start += len(pick)
        if np.any(np.abs(own[2]) > bound):  # gravity beyond a limit: the estimate without torques
            x = phase_plane_profile(d1, d2, steps, velocity, acceleration, np.zeros_like(d1))
            times, window, usage = profile_window(
                x, steps, d1, jerk, window_s, rounds, tolerance, second_share
            )
            durations[s] = jerk_limited_duration(times, window, usage, second_share)
            continue
        contiguous = np.ascontiguousarray(own)
        durations[s] = torque_limited_duration(
            steps, d1, d2, pick, contiguous, bound, limits, window_s, rounds, tolerance, second_share
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
