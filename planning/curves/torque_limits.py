"""Torque limits in the timing: the rows the phase plane keeps, and the exact uniform time scale.

Along a path ``q(s)`` run at speed ``s'`` the joint torques are affine in the path
acceleration and the squared speed: ``tau = slope s'' + curve s'^2 + offset``
(:meth:`TorqueModel.path_terms`), the form of a joint's acceleration with an offset, gravity's
torque. :func:`torque_rows` turns them into rows the phase plane
(:mod:`planning.curves.phase_plane`) keeps beside the joints' accelerations, under the effort
limits less :data:`HEADROOM`.

Run uniformly ``k`` times slower, a trajectory's torques are ``d / k^2 + g``, with ``g`` the
gravity torque and ``d`` the rest (inertia, Coriolis): :func:`torque_time_scale` gives the
least ``k`` that keeps every sample within the limits, in closed form. This module knows no
robot: a :class:`TorqueModel` (:class:`cpr_kin.kinematics.dynamics.Dynamics`) computes the torques.
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.arrays import distinct_sorted
from planning.curves.phase_plane import path_acceleration
from planning.curves.trajectory import Trajectory

FloatArray = NDArray[np.float64]

HEADROOM = 1e-3
"""Share of the effort limits the timing leaves unused: a check sampling other instants than
the timing's (``cpr-plan check`` every millisecond) finds peaks between them a little higher."""
COARSE_STEP_S = 1e-2
"""Spacing of the samples at which :func:`torque_time_scale` first evaluates the torques [s]."""
PRECHECK_STRIDE = 4
"""Every how many grid points :func:`torque_rows` first looks whether the torques bind."""
FINE_STEP_S = 1e-3
"""Spacing of its samples around the coarse samples that come near the largest scale [s] (the
verification's step, ``planning.pipeline.torques.CHECK_STEP_S``)."""
PEAK_STEP_S = 1e-4
"""Spacing of its last samples, within a fine step of each peak of the fine samples [s]."""
UNBOUND_SHARE = 0.9
"""Share of a limit below which a torque is taken not to bind, where a cheaper answer holds:
:func:`torque_rows` leaves out the rows of a profile whose torques all stay below it, and
:func:`torque_time_scale` refines only samples that need more than this share of the scale."""


class TorqueModel(Protocol):
    """The joint torques of a robot (:class:`cpr_kin.kinematics.dynamics.Dynamics`)."""

    @property
    def effort(self) -> FloatArray:
        """``(nj,)`` effort limits [N m or N], ``inf`` where unknown."""
        ...

    def torques(
        self, q: FloatArray, qd: FloatArray | None = None, qdd: FloatArray | None = None
    ) -> FloatArray:
        """``(T, nj)`` torques at ``(T, nj)`` positions, velocities and accelerations."""
        ...

    def path_terms(
        self, q: FloatArray, dq: FloatArray, ddq: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``slope``, ``curve``, ``offset`` ``(T, nj)`` of the torques along a path (module docstring)."""
        ...


class TorqueRows(NamedTuple):
    """Torque constraints at the grid points of a path: ``|slope s'' + curve s'^2 + offset| <= limit``."""

    slope: FloatArray
    """``(G, R)`` torque per unit path acceleration."""
    curve: FloatArray
    """``(G, R)`` torque per unit squared path speed."""
    offset: FloatArray
    """``(G, R)`` gravity's torque."""
    limit: FloatArray
    """``(R,)`` effort limits less :data:`HEADROOM`."""


def phase_plane_rows(
    dq: FloatArray, ddq: FloatArray, velocity: FloatArray, acceleration: FloatArray, rows: TorqueRows | None
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """The joints' rows and the torque ``rows`` as the arguments of ``phase_plane_profile`` but the steps.

    ``(d1, d2, v, a, offset)``: the joints' ``dq``, ``ddq`` ``(G, nj)`` with their limits and no
    offset, then the torques' slope, curve, effort limit and gravity offset (no velocity limit).
    """
    if rows is None:
        return dq, ddq, velocity, acceleration, np.zeros_like(dq)
    return (
        np.hstack([dq, rows.slope]),
        np.hstack([ddq, rows.curve]),
        np.concatenate([velocity, np.full(len(rows.limit), np.inf)]),
        np.concatenate([acceleration, rows.limit]),
        np.hstack([np.zeros_like(dq), rows.offset]),
    )


def profile_torques(
    terms: tuple[FloatArray, FloatArray, FloatArray], x: FloatArray, push: FloatArray
) -> FloatArray:
    """The torques ``(G, R)`` of a profile from their ``terms`` (slope, curve, offset).

    At ``x = s'^2`` and the path acceleration ``push = s''``.
    """
    slope, curve, offset = terms
    return np.asarray(slope * push[:, None] + curve * x[:, None] + offset)


def torque_rows(
    q: FloatArray, dq: FloatArray, ddq: FloatArray, ds: FloatArray, model: TorqueModel, x: FloatArray
) -> TorqueRows | None:
    """The rows of the joints with a known effort limit along the path ``q(s)`` ``(G, nj)``.

    ``None`` when they cannot bind, or cannot be kept:

    - no joint has a known effort limit;
    - the profile ``x = s'^2`` without them (on the grid steps ``ds``) stays below
      :data:`UNBOUND_SHARE` of every limit: a cap on it only lowers the speeds, so the rows
      would change nothing but the cost (the final :func:`torque_time_scale` still holds
      every torque to its limit);
    - gravity alone exceeds a limit somewhere on the path: standing there is beyond the
      motors, and the phase plane's rest-to-rest profile assumes it is not (the
      verification then names the torque, as the timing cannot help).
    """
    limited = np.isfinite(model.effort)
    if not limited.any():
        return None
    limit = model.effort[limited] * (1.0 - HEADROOM)
    push = path_acceleration(x, ds)
    for points in (slice(None, None, PRECHECK_STRIDE), slice(None)):  # a cheap look first
        slope, curve, offset = (
            term[:, limited] for term in model.path_terms(q[points], dq[points], ddq[points])
        )
        if np.any(np.abs(offset) > limit):
            return None
        if np.all(
            np.abs(profile_torques((slope, curve, offset), x[points], push[points])) <= UNBOUND_SHARE * limit
        ):
            return None
    return TorqueRows(slope, curve, offset, limit)


def torque_time_scale(trajectory: Trajectory, model: TorqueModel, at_least: float = 0.0) -> float:
    """The least uniform time scale ``k`` whose trajectory keeps the torques within the limits.

    Limits less :data:`HEADROOM`, at samples every :data:`COARSE_STEP_S` and at the knots,
    then every :data:`FINE_STEP_S` within a coarse step of the samples within
    :data:`UNBOUND_SHARE` of the largest scale (that or ``at_least``, a scale another limit
    needs: when every coarse sample needs less than :data:`UNBOUND_SHARE` of it, the torques
    do not bind and the coarse answer is returned), and last every :data:`PEAK_STEP_S` within
    a fine step of the fine samples' peaks (:func:`local_peaks`). ``0`` when no torque binds
    however fast (no known limit, or none moves it); ``inf`` when gravity alone exceeds a
    limit at a sample (no scale helps).
    """
    limited = np.isfinite(model.effort)
    if not limited.any():
        return 0.0
    start, end = float(trajectory.knots[0]), float(trajectory.knots[-1])
    count = max(2, int(np.ceil((end - start) / COARSE_STEP_S)) + 1)
    coarse = distinct_sorted(np.linspace(start, end, count), trajectory.knots)
    needed = _needed_scales(trajectory, model, limited, coarse)
    top = max(float(needed.max()), at_least)
    if not np.isfinite(top) or needed.max() < UNBOUND_SHARE * top:
        return float(needed.max())
    near = coarse[needed >= UNBOUND_SHARE * top]
    fine = _around(near, COARSE_STEP_S, FINE_STEP_S, start, end)
    fine_needed = _needed_scales(trajectory, model, limited, fine)
    peaks = fine[local_peaks(fine_needed, UNBOUND_SHARE * top)]
    if not peaks.size:  # no fine peak at or above the floor: nothing to look at closer
        return float(max(needed.max(), fine_needed.max()))
    finest = _needed_scales(trajectory, model, limited, _around(peaks, FINE_STEP_S, PEAK_STEP_S, start, end))
    return float(max(needed.max(), fine_needed.max(), finest.max()))


def local_peaks(values: FloatArray, floor: float) -> NDArray[np.bool_]:
    """``(T,)`` where ``values`` ``(T,)`` is a local maximum at least ``floor``.

    A local maximum is at least both its neighbours (an end: its one); a plateau's samples all are.
    """
    padded = np.pad(values, 1, constant_values=-np.inf)
    return np.asarray((values >= padded[:-2]) & (values >= padded[2:]) & (values >= floor))


def _around(centres: FloatArray, reach: float, step: float, start: float, end: float) -> FloatArray:
    """Times every ``step`` within ``reach`` of each of ``centres`` [s] in ``[start, end]``, sorted."""
    offsets = np.arange(-reach, reach + step / 2, step)
    return distinct_sorted(np.clip((centres[:, None] + offsets).ravel(), start, end))


def _needed_scales(
    trajectory: Trajectory, model: TorqueModel, limited: NDArray[np.bool_], t: FloatArray
) -> FloatArray:
    """``(T,)`` the least time scale each sample at ``t`` [s] needs (module docstring)."""
    q, qd, qdd = (trajectory(t, r) for r in range(3))
    gravity = model.torques(q)[:, limited]
    moving = model.torques(q, qd, qdd)[:, limited] - gravity
    limit = model.effort[limited] * (1.0 - HEADROOM)
    room = np.where(moving > 0.0, limit - gravity, limit + gravity)  # toward the limit it pushes
    with np.errstate(divide="ignore", invalid="ignore"):
        needed = np.where(room > 0.0, np.sqrt(np.abs(moving) / np.maximum(room, 1e-300)), np.inf)
    return np.asarray(needed.max(axis=1))
