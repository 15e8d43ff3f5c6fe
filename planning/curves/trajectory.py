"""Piecewise-polynomial joint trajectories: evaluation, exact extrema, time scaling.

Segment ``i`` covers ``knots[i] <= t <= knots[i + 1]`` and joint ``j`` follows
``q_j(t) = sum_k coefficients[i, j, k] (t - knots[i])^k`` (local seconds, the layout of the
``cpr-trajectory/1`` file).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planning.curves.segment_extrema import extremum_candidates
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

DERIVATIVE_NAMES = ("position", "velocity", "acceleration", "jerk", "snap")


def derivative_coefficients(coefficients: FloatArray, r: int) -> FloatArray:
    """Power coefficients ``(..., order)`` of the r-th derivative, zero-padded at the top."""
    order = coefficients.shape[-1]
    k = np.arange(order)
    factor = np.ones(order)
    for m in range(r):
        factor = factor * (k - m)
    out = np.zeros_like(coefficients)
    out[..., : order - r] = (coefficients * factor)[..., r:]
    return out


def interval_speed_bounds(
    times: FloatArray, velocity: FloatArray, peak_speed: FloatArray, peak_acceleration: FloatArray
) -> FloatArray:
    """``(K - 1, nq)`` bounds on ``|q'_j|`` over each interval between the sorted ``times`` ``(K,)``.

    ``velocity`` ``(K, nq)`` at the times [rad/s or m/s], bounded by ``peak_speed``, whose
    rate is bounded by ``peak_acceleration`` [rad/s^2 or m/s^2]: from either end of an
    interval of length ``dt`` the speed rises at most that fast, so it stays below
    ``(|q'_j(t_k)| + |q'_j(t_k+1)| + A_j dt) / 2``, and never above the peak.
    """
    speed = np.abs(velocity)
    rising = 0.5 * (speed[:-1] + speed[1:] + peak_acceleration * np.diff(times)[:, None])
    return np.asarray(np.minimum(rising, peak_speed))


@dataclass(frozen=True)
class Extrema:
    """Exact extrema of one derivative of every joint over the whole trajectory.

    Attributes:
        derivative: derivative order (1 velocity, 2 acceleration, 3 jerk).
        minimum: ``(nj,)`` smallest value per joint.
        maximum: ``(nj,)`` largest value per joint.
        time_of_minimum: ``(nj,)`` [s].
        time_of_maximum: ``(nj,)`` [s].
    """

    derivative: int
    minimum: FloatArray
    maximum: FloatArray
    time_of_minimum: FloatArray
    time_of_maximum: FloatArray

    def __post_init__(self) -> None:
        for name in ("minimum", "maximum", "time_of_minimum", "time_of_maximum"):  # own, read-only copies
            array = np.array(getattr(self, name), dtype=float)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @property
    def peak(self) -> FloatArray:
        """``(nj,)`` largest absolute value per joint."""
        return np.asarray(np.maximum(np.abs(self.minimum), np.abs(self.maximum)))

    def time_scaled(self, start_s: float, scale: float) -> Extrema:
        """These extrema once the trajectory runs ``scale`` times slower from ``start_s`` [s].

        Its r-th derivative at ``start_s + scale (t - start_s)`` is ``scale^-r`` times this one's at ``t``.
        """
        factor = float(scale) ** -self.derivative
        stretched = (start_s + (t - start_s) * scale for t in (self.time_of_minimum, self.time_of_maximum))
        return Extrema(self.derivative, self.minimum * factor, self.maximum * factor, *stretched)


@dataclass(frozen=True)
class Trajectory:
    """A piecewise-polynomial joint trajectory, immutable.

    Attributes:
        knots: ``(N + 1,)`` increasing segment boundaries [s].
        coefficients: ``(N, nj, order)`` power coefficients in local seconds.

    """

    knots: FloatArray
    coefficients: FloatArray
    _derivatives: dict[int, FloatArray] = field(default_factory=dict, init=False, repr=False, compare=False)
    _extrema: dict[int, Extrema] = field(default_factory=dict, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        knots = np.array(self.knots, dtype=float)
        coefficients = np.array(self.coefficients, dtype=float, order="C")  # one compiled `evaluate`
        if knots.ndim != 1 or len(knots) < 2 or not (knots[1:] > knots[:-1]).all():
            raise PlanningError(
                f"trajectory knots {knots.tolist()} must be at least two increasing times [s]"
            )
        if coefficients.ndim != 3 or coefficients.shape[0] != len(knots) - 1:
            raise PlanningError(
                f"trajectory coefficients of shape {coefficients.shape}; expected "
                f"({len(knots) - 1}, joints, order)"
            )
        for array in (knots, coefficients):
            array.setflags(write=False)
        object.__setattr__(self, "knots", knots)
        object.__setattr__(self, "coefficients", coefficients)

    @property
    def duration(self) -> float:
        """Total duration [s]."""
        return float(self.knots[-1] - self.knots[0])

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return int(self.coefficients.shape[1])

    @property
    def n_segments(self) -> int:
        """Number of polynomial segments N."""
        return int(self.coefficients.shape[0])

    def _coefficients(self, derivative: int) -> FloatArray:
        if derivative not in self._derivatives:
            self._derivatives[derivative] = derivative_coefficients(self.coefficients, derivative)
        return self._derivatives[derivative]

    def __call__(self, t: ArrayLike, derivative: int = 0) -> FloatArray:
        """Evaluate the ``derivative``-th derivative at times ``t`` [s].

        Returns ``(nj,)`` for a scalar time, ``(K, nj)`` for ``K`` times. Times outside the
        knots are clamped to the ends.

        Raises:
            PlanningError: a derivative order the polynomials do not have, or a time that is
                not a finite number (NaN would come back as NaN positions).
        """
        if derivative < 0 or derivative >= self.coefficients.shape[2]:
            raise PlanningError(
                f"derivative order {derivative} must be in [0, {self.coefficients.shape[2] - 1}]"
            )
        from planning.curves.horner import evaluate  # compiled: numba only once a trajectory is evaluated

        times = np.asarray(t, dtype=float)
        if not np.isfinite(times).all():
            bad = times[~np.isfinite(times)].ravel()[0] if times.ndim else times
            raise PlanningError(f"time t = {float(bad)} s must be a finite number [s]")
        value = evaluate(self._coefficients(derivative), self.knots, np.atleast_1d(times).ravel())
        return np.asarray(value[0] if times.ndim == 0 else value)

    def position(self, t: ArrayLike) -> FloatArray:
        """Joint positions [rad, m] at ``t`` [s]."""
        return self(t, 0)

    def velocity(self, t: ArrayLike) -> FloatArray:
        """Joint velocities [rad/s, m/s] at ``t`` [s]."""
        return self(t, 1)

    def acceleration(self, t: ArrayLike) -> FloatArray:
        """Joint accelerations [rad/s^2, m/s^2] at ``t`` [s]."""
        return self(t, 2)

    def jerk(self, t: ArrayLike) -> FloatArray:
        """Joint jerks [rad/s^3, m/s^3] at ``t`` [s]."""
        return self(t, 3)

    def snap(self, t: ArrayLike) -> FloatArray:
        """Joint snaps [rad/s^4, m/s^4] at ``t`` [s] (discontinuous at the knots)."""
        return self(t, 4)

    def speed_bounds(self, times: FloatArray) -> FloatArray:
        """:func:`interval_speed_bounds` of this trajectory between the sorted ``times`` ``(K,)``.

        Near rest (the ends of a motion) far below the peak speed [rad/s or m/s].
        """
        return interval_speed_bounds(times, self.velocity(times), self.extrema(1).peak, self.extrema(2).peak)

    def extrema(self, derivative: int) -> Extrema:
        """Exact extrema of the ``derivative``-th derivative per joint.

        Candidates are the segment ends and the real roots of the next derivative inside
        the segments that may hold an extremum (:mod:`planning.curves.segment_extrema`); no
        sampling is involved. Computed once per order (the trajectory is immutable).
        """
        if derivative in self._extrema:
            return self._extrema[derivative]
        n, nj, order = self.coefficients.shape
        h = np.diff(self.knots)
        value = self._coefficients(derivative).reshape(n * nj, order)
        slope = self._coefficients(derivative + 1).reshape(n * nj, order)
        local = extremum_candidates(value, slope, np.repeat(h, nj), nj)  # (n nj, K), nan: none
        values = np.zeros_like(local)
        for k in range(order - 1, -1, -1):  # Horner, all candidates at once (nan stays nan)
            values = values * local + value[:, k : k + 1]
        values = values.reshape(n, nj, -1).transpose(1, 0, 2).reshape(nj, -1)  # per joint
        times = (self.knots[:-1, None, None] + local.reshape(n, nj, -1)).transpose(1, 0, 2).reshape(nj, -1)
        low = np.nanargmin(values, axis=1)
        high = np.nanargmax(values, axis=1)
        joints = np.arange(nj)
        minimum, maximum = values[joints, low], values[joints, high]
        t_min, t_max = times[joints, low], times[joints, high]
        self._extrema[derivative] = Extrema(derivative, minimum, maximum, t_min, t_max)
        return self._extrema[derivative]

    def knot_jumps(self, orders: int = 4) -> tuple[FloatArray, FloatArray]:
        """Jumps of the derivatives ``0 .. orders - 1`` at the interior knots.

        Returns ``(jump, relative)``, each ``(N - 1, nj, orders)``: ``jump`` is
        ``|left - right|``, the end of segment ``i`` minus the start of segment ``i + 1``
        [rad/s^r or m/s^r]; ``relative`` is it over the largest magnitude summed to evaluate
        either side (rounding alone gives about 1e-15; a C3 spline's are that small).
        """
        n, nj, order = self.coefficients.shape
        if n < 2:
            empty = np.zeros((0, nj, orders))
            return empty, empty
        h = np.diff(self.knots)[:-1, None, None]  # (N - 1, 1, 1)
        k = np.arange(order)
        jump = np.zeros((n - 1, nj, orders))
        relative = np.zeros((n - 1, nj, orders))
        for r in range(orders):
            factor = np.ones(order)
            for m in range(r):
                factor = factor * (k - m)
            terms = self.coefficients[:-1] * factor * h ** np.maximum(k - r, 0)  # (N - 1, nj, order)
            left = terms.sum(axis=2)
            right = self.coefficients[1:, :, r] * factor[r]
            scale = np.maximum(np.abs(terms).max(axis=2), np.abs(right))
            jump[:, :, r] = np.abs(left - right)
            relative[:, :, r] = np.where(scale > 0, jump[:, :, r] / np.where(scale > 0, scale, 1.0), 0.0)
        return jump, relative

    @cached_property
    def integrated_squared_jerk(self) -> FloatArray:
        """``(nj,)`` integral of the squared jerk over the trajectory [rad^2/s^5, m^2/s^5]."""
        jerk = self._coefficients(3)
        n, nj, order = jerk.shape
        square = np.zeros((n, nj, 2 * order - 1))
        for k in range(order):
            square[..., k : k + order] += jerk[..., k : k + 1] * jerk
        powers = np.arange(square.shape[2]) + 1
        h = np.diff(self.knots)[:, None, None]
        integral = (square * h**powers / powers).sum(axis=2)
        return np.asarray(integral.sum(axis=0))

    def between(self, t0: float, t1: float) -> Trajectory:
        """The piece over ``[t0, t1]`` [s], two of its knots (within 1e-9 s): a task's segment."""
        first, last = (int(np.argmin(np.abs(self.knots - t))) for t in (t0, t1))
        if max(abs(self.knots[first] - t0), abs(self.knots[last] - t1)) > 1e-9 or last <= first:
            raise PlanningError(f"[{t0:g}, {t1:g}] s are not two knots of the trajectory, in order")
        return Trajectory(self.knots[first : last + 1], self.coefficients[first:last])

    def time_scaled(self, scale: float) -> Trajectory:
        """The same path run ``scale`` times slower: ``q'(t) = q(t0 + (t - t0) / scale)``.

        Knots stretch by ``scale`` and the r-th derivative (its extrema found too) shrinks by ``scale^-r``.
        """
        if not (np.isfinite(scale) and scale > 0):
            raise PlanningError(f"time scale {scale} must be a finite number > 0")
        powers = float(scale) ** -np.arange(self.coefficients.shape[2])
        knots = self.knots[0] + (self.knots - self.knots[0]) * scale
        scaled = Trajectory(knots=knots, coefficients=self.coefficients * powers)
        for derivative, found in self._extrema.items():  # known here: scaled, not searched again
            scaled._extrema[derivative] = found.time_scaled(float(self.knots[0]), scale)
        return scaled

    def time_scale_for_limits(
        self, velocity: ArrayLike, acceleration: ArrayLike | None = None, jerk: ArrayLike | None = None
    ) -> float:
        """Smallest uniform time scale ``s`` that keeps every joint within the given limits.

        ``time_scaled(s)`` then reaches a limit exactly (``s < 1`` speeds a slow trajectory
        up). Limits are per joint [rad/s^r, m/s^r]; ``None`` skips that order.
        """
        scale = 0.0
        for r, limit in enumerate((velocity, acceleration, jerk), start=1):
            if limit is None:
                continue
            bound = np.broadcast_to(np.asarray(limit, dtype=float), (self.n_joints,))
            if not np.all(np.isfinite(bound) & (bound > 0)):
                raise PlanningError(f"{DERIVATIVE_NAMES[r]} limits {bound.tolist()} must be finite and > 0")
            ratio = float(np.max(self.extrema(r).peak / bound))
            scale = max(scale, ratio ** (1.0 / r))
        if scale == 0.0:
            raise PlanningError("the trajectory does not move: no time scale reaches a limit")
        return scale
