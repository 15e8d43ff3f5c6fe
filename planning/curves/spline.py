"""Septic smoothing spline after Simon (2004), the paper's eq. 8-19.

For every joint, the node values ``y, y', y'', y'''`` at the knots ``t_0 .. t_N`` minimise

    J = sum_i p_i (y_i - f_i)^2 + int a1 y'^2 + a2 y''^2 + a3 y'''^2 dt

over degree-7 Hermite segments (:mod:`planning.curves.hermite`), so that position, velocity,
acceleration and jerk are continuous. On a segment of duration ``h`` the r-th derivative is
``h^-r`` times the derivative in the normalised time ``tau`` and ``dt = h dtau``: the ``a_r``
term carries ``h^(1 - 2r)``. J is quadratic in the ``4 (N + 1)`` unknowns; ordered node by
node, segment ``i`` touches unknowns ``4i .. 4i + 7``, so the normal equations are symmetric,
banded (half-bandwidth 7) and positive definite once some ``a_r > 0``. Values that are not
free are eliminated before the solve, never approximated by a huge weight:

- nodes with ``p_i = inf`` (exact interpolation), and the first and last node unless
  ``exact_ends = False`` (a robot leaves from where it stands and arrives where it is sent);
- with ``ends = "rest"``, velocity and acceleration at both ends (zero).

With ``ends = "natural"`` nothing more is imposed: the optimum's own boundary conditions
(``y''' = y'''' = 0`` at the ends under jerk-only smoothing) are the paper's.
All joints share the matrix: :class:`SepticSplineSolver` factorises it once (LAPACK banded
Cholesky) and solves every joint, or every candidate of an optimiser, as columns of one
right-hand side.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planning.curves.banded_cholesky import band_cholesky_solve
from planning.curves.banded_system import PER_NODE, factorised_system
from planning.curves.hermite import HERMITE_INV, node_scaling
from planning.curves.spline_settings import SplineSettings
from planning.curves.trajectory import Trajectory
from planning.errors import SplineError

FloatArray = NDArray[np.float64]

DENSE_MAP_NODES = 16
"""Up to this many nodes, :meth:`SepticSplineSolver.solve_batch` applies the dense map."""


@dataclass(frozen=True)
class SplineFit:
    """A solved septic smoothing spline.

    Attributes:
        trajectory: the spline as a piecewise polynomial in local seconds.
        targets: ``(N + 1, nj)`` the node values ``f_i`` it was asked to pass near.
        nodes: ``(N + 1, nj, 4)`` the solved ``y, y', y'', y'''`` at the knots.
        settings: the settings used.

    """

    trajectory: Trajectory
    targets: FloatArray
    nodes: FloatArray
    settings: SplineSettings

    @property
    def node_deviation(self) -> FloatArray:
        """``(N + 1, nj)`` signed deviation ``y_i - f_i`` [rad, m]."""
        return np.asarray(self.nodes[:, :, 0] - self.targets)

    @property
    def max_node_deviation(self) -> float:
        """Largest absolute node deviation over all nodes and joints [rad, m]."""
        return float(np.abs(self.node_deviation).max())


def _lowest_weighted_order(settings: SplineSettings) -> int:
    return 1 + next(r for r, coef in enumerate(settings.a) if coef > 0)


class SepticSplineSolver:
    """The septic smoothing spline for fixed knots and settings, factorised once.

    Building it assembles and factorises the banded system; :meth:`solve` then fits any
    node values, and :meth:`solve_batch` many sets at once (columns of one right-hand
    side), which is what an optimiser evaluating many candidates needs. The fit is linear
    in the node values: for at most :data:`DENSE_MAP_NODES` nodes, :meth:`solve_batch`
    applies the precomputed map from node values to coefficients (:attr:`coefficient_map`),
    one small product instead of two banded triangular solves per call.

    Args:
        knots: ``(N + 1,)`` strictly increasing node times [s] (non-uniform allowed).
        settings: weights and end conditions (default: the paper's).

    Raises:
        SplineError: non-finite or non-increasing knots, too few nodes, or a ``p`` of the
            wrong length.

    """

    def __init__(self, knots: ArrayLike, settings: SplineSettings | None = None) -> None:
        self.settings = settings = settings or SplineSettings()
        t = np.array(knots, dtype=float)
        if t.ndim != 1:
            raise SplineError(f"knots of shape {t.shape}; expected (N + 1,) node times [s]")
        if not np.all(np.isfinite(t)):
            raise SplineError(f"knots {t.tolist()} must be finite numbers (no NaN or inf)")
        steps = np.diff(t)
        if np.any(steps <= 0):
            bad = int(np.argmax(steps <= 0))
            raise SplineError(
                f"knots must increase strictly; t[{bad}] = {t[bad]} >= t[{bad + 1}] = {t[bad + 1]}"
            )
        order = _lowest_weighted_order(settings)
        if len(t) < max(2, order):
            raise SplineError(
                f"{len(t)} node(s) given; a spline whose lowest weighted derivative is order {order} "
                f"needs at least {max(2, order)}"
            )
        p = np.asarray(settings.p, dtype=float)
        if p.ndim == 1 and len(p) != len(t):
            raise SplineError(f"{len(p)} node weights p for {len(t)} nodes; give one value or one per node")
        t.setflags(write=False)
        self.knots = t
        n_nodes = len(t)
        p = np.full(n_nodes, float(p)) if p.ndim == 0 else p

        exact = ~np.isfinite(p)
        if settings.exact_ends:
            exact[[0, -1]] = True
        self._factor, self._coupling = factorised_system(steps, settings.a, p, exact, settings.ends)
        # Hermite data of both ends of a segment -> power coefficients in local seconds
        seconds = steps[:, None] ** -np.arange(HERMITE_INV.shape[0], dtype=float)
        self._to_coefficients = seconds[:, :, None] * HERMITE_INV[None] * node_scaling(steps)[:, None, :]

    @property
    def n_nodes(self) -> int:
        """Number of nodes N + 1."""
        return len(self.knots)

    def _solve_nodes(self, values: FloatArray) -> FloatArray:
        rhs = np.asarray(self._coupling @ values, dtype=float)
        solution = band_cholesky_solve(self._factor, np.ascontiguousarray(rhs.reshape(len(rhs), -1)))
        return solution.reshape(rhs.shape)

    def _coefficients(self, solution: FloatArray) -> FloatArray:
        nodes = solution.reshape(self.n_nodes, PER_NODE, -1)
        hermite = np.concatenate([nodes[:-1], nodes[1:]], axis=1)  # (N, 8, m): both ends
        return np.asarray(np.matmul(self._to_coefficients, hermite).transpose(0, 2, 1))

    def _check_values(self, values: ArrayLike) -> FloatArray:
        f = np.asarray(values, dtype=float)
        if f.ndim == 1:
            f = f[:, None]
        if f.ndim != 2 or len(f) != self.n_nodes:
            raise SplineError(
                f"node values of shape {np.shape(values)} do not match the {self.n_nodes} knots; "
                "expected (N + 1,) or (N + 1, joints)"
            )
        if not np.all(np.isfinite(f)):
            raise SplineError("node values must be finite numbers (no NaN or inf)")
        return f

    def solve(self, targets: ArrayLike) -> SplineFit:
        """Fit node values ``targets``: ``(N + 1,)`` or ``(N + 1, nj)`` [rad, m]."""
        f = self._check_values(targets)
        solution = self._solve_nodes(f)
        nodes = solution.reshape(self.n_nodes, PER_NODE, f.shape[1]).transpose(0, 2, 1)
        trajectory = Trajectory(knots=self.knots, coefficients=self._coefficients(solution))
        return SplineFit(trajectory=trajectory, targets=f, nodes=nodes, settings=self.settings)

    @cached_property
    def coefficient_map(self) -> FloatArray:
        """``(N, 8, N + 1)`` linear map ``C`` from node values to power coefficients.

        ``coefficients[i, :, k] = C[i, k] @ f`` for node values ``f`` ``(N + 1, m)``: the
        fit of every unit vector. Exact values (pinned nodes, rest ends) are reproduced
        exactly: their rows of the solution are the identity.
        """
        unit_fits = self._coefficients(self._solve_nodes(np.eye(self.n_nodes)))  # (N, nodes, 8)
        mapping = np.ascontiguousarray(unit_fits.transpose(0, 2, 1))
        mapping.setflags(write=False)
        return mapping

    def solve_batch(self, targets: ArrayLike) -> FloatArray:
        """Power coefficients ``(N, m, 8)`` in local seconds for ``(N + 1, m)`` node values.

        The fast path for many candidates at once: no :class:`SplineFit` objects. For few
        nodes it applies :attr:`coefficient_map`; the result is then a transposed view.
        """
        f = self._check_values(targets)
        if self.n_nodes <= DENSE_MAP_NODES:
            return np.asarray(np.matmul(self.coefficient_map, f).transpose(0, 2, 1))
        return self._coefficients(self._solve_nodes(f))


def fit_septic_spline(
    knots: ArrayLike, targets: ArrayLike, settings: SplineSettings | None = None
) -> SplineFit:
    """Solve the septic smoothing spline through ``targets`` at ``knots``.

    Args:
        knots: ``(N + 1,)`` strictly increasing node times [s] (non-uniform allowed).
        targets: ``(N + 1,)`` or ``(N + 1, nj)`` node values ``f_i`` [rad, m], all joints at once.
        settings: weights and end conditions (default: the paper's, ``p = 1e6``,
            ``a = (0, 0, 1)``, natural ends).

    Raises:
        SplineError: NaN input, non-increasing knots, too few nodes, bad settings.

    """
    return SepticSplineSolver(knots, settings).solve(targets)


def uniform_knots(n_segments: int, duration: float) -> FloatArray:
    """``n_segments + 1`` evenly spaced knots over ``[0, duration]`` [s]."""
    if n_segments < 1 or not (np.isfinite(duration) and duration > 0):
        raise SplineError(f"{n_segments} segments over {duration} s: need >= 1 segment and a duration > 0")
    return np.linspace(0.0, duration, n_segments + 1)
