from __future__ import annotations

import itertools
import re

import numpy as np
import pytest
from scipy.interpolate import BSpline, make_interp_spline

import cpr_kin as ck
from planning.curves.spline import (
    DENSE_MAP_NODES,
    SepticSplineSolver,
    fit_septic_spline,
    uniform_knots,
)
from planning.curves.spline_settings import SplineSettings
from planning.errors import SplineError

from .conftest import PAPER_GOAL_TCP, PAPER_START_TCP

INF = float("inf")
NATURAL_QUINTIC = "natural"


def knots_and_values(
    rng: np.random.Generator, n_segments: int, uniform: bool, joints: int = 3
) -> tuple[np.ndarray, np.ndarray]:
    steps = np.ones(n_segments) if uniform else rng.uniform(0.3, 2.0, n_segments)
    return np.concatenate([[0.0], np.cumsum(steps)]), rng.normal(size=(n_segments + 1, joints))


def scipy_quintic(t: np.ndarray, f: np.ndarray, ends: str) -> BSpline:
    z = np.zeros(f.shape[1])
    orders = (3, 4) if ends == "natural" else (1, 2)
    bc = ([(orders[0], z), (orders[1], z)], [(orders[0], z), (orders[1], z)])
    return make_interp_spline(t, f, k=5, bc_type=bc)


@pytest.mark.parametrize("uniform", [True, False])
@pytest.mark.parametrize("ends", ["natural", "rest"])
def test_exact_jerk_only_is_the_quintic_interpolating_spline(
    rng: np.random.Generator, uniform: bool, ends: str
) -> None:
    t, f = knots_and_values(rng, 7, uniform)
    fit = fit_septic_spline(t, f, SplineSettings(p=INF, a=(0, 0, 1), ends=ends))  # type: ignore[arg-type]
    reference = scipy_quintic(t, f, ends)
    times = np.linspace(t[0], t[-1], 997)
    for r in range(4):
        np.testing.assert_allclose(fit.trajectory(times, r), reference(times, r), atol=1e-8 * 10**r)
    assert fit.max_node_deviation == 0.0


@pytest.mark.parametrize("exact_ends", [False, True])
def test_jerk_only_smoothing_structure(rng: np.random.Generator, exact_ends: bool) -> None:
    t, f = knots_and_values(rng, 6, uniform=False)
    p = 50.0
    fit = fit_septic_spline(t, f, SplineSettings(p=p, a=(0, 0, 1), exact_ends=exact_ends))
    c = fit.trajectory.coefficients
    scale = np.abs(c).max()
    # the optimum is piecewise quintic: tau^6 and tau^7 vanish
    np.testing.assert_allclose(c[..., 6:], 0.0, atol=1e-9 * scale)
    # y'''' is continuous at the interior knots
    inner = t[1:-1]
    np.testing.assert_allclose(
        fit.trajectory(inner - 1e-12, 4), fit.trajectory(inner + 1e-12, 4), atol=1e-6 * scale
    )
    # a3 [y^(5)]_i = p_i (y_i - f_i): the jump of the 5th derivative is the node's pull
    left = np.zeros_like(f)
    right = np.zeros_like(f)
    fifth = 120.0 * c[..., 5]  # y^(5) is constant on each segment
    right[:-1] = fifth
    left[1:] = fifth
    jump = right - left
    nodes = slice(1, -1) if exact_ends else slice(None)
    np.testing.assert_allclose(jump[nodes], p * fit.node_deviation[nodes], atol=1e-6 * np.abs(jump).max())
    if exact_ends:
        assert np.all(fit.node_deviation[[0, -1]] == 0.0)


def test_polynomial_reproduction(rng: np.random.Generator) -> None:
    t, _ = knots_and_values(rng, 6, uniform=False)
    quadratic = np.column_stack([1 + 2 * t - 0.5 * t**2, -3 + 0.1 * t**2])
    fit = fit_septic_spline(t, quadratic, SplineSettings(p=10.0, a=(0, 0, 1)))
    times = np.linspace(t[0], t[-1], 301)
    expected = np.column_stack([1 + 2 * times - 0.5 * times**2, -3 + 0.1 * times**2])
    np.testing.assert_allclose(fit.trajectory(times), expected, atol=1e-10)
    line = np.column_stack([2 - 0.7 * t])
    fit = fit_septic_spline(t, line, SplineSettings(p=10.0, a=(0, 1, 0)))
    np.testing.assert_allclose(fit.trajectory(times)[:, 0], 2 - 0.7 * times, atol=1e-10)


def fifth_derivative_jumps(fit_coefficients: np.ndarray) -> np.ndarray:
    """Right minus left 5th derivative at the interior knots of a piecewise quintic."""
    fifth = 120.0 * fit_coefficients[..., 5]
    return np.asarray(fifth[1:] - fifth[:-1])


def test_deviation_times_p_tends_to_a_constant(rng: np.random.Generator) -> None:
    t, f = knots_and_values(rng, 5, uniform=True)
    products = []
    for p in (1e4, 1e5, 1e6, 1e7):
        fit = fit_septic_spline(t, f, SplineSettings(p=p))
        products.append(fit.node_deviation[1:-1] * p)
    changes = [np.abs(products[k + 1] - products[k]).max() for k in range(3)]
    assert changes[2] < changes[1] < changes[0]
    # the limit is the 5th-derivative jump of the exact interpolating spline (a3 = 1)
    exact = fit_septic_spline(t, f, SplineSettings(p=INF))
    limit = fifth_derivative_jumps(exact.trajectory.coefficients)
    assert np.abs(limit).max() > 1.0
    np.testing.assert_allclose(products[-1], limit, rtol=1e-5, atol=1e-5 * np.abs(limit).max())


def test_time_scaling_law(rng: np.random.Generator) -> None:
    t, f = knots_and_values(rng, 6, uniform=False)
    settings = SplineSettings(p=200.0, a=(0.3, 0.2, 1.0), ends="rest")
    fit = fit_septic_spline(t, f, settings)
    for s in (0.5, 3.0):
        scaled = fit_septic_spline(t * s, f, settings.scaled_for_time(s))
        np.testing.assert_allclose(scaled.nodes[..., 0], fit.nodes[..., 0], atol=1e-10)
        times = np.linspace(t[0], t[-1], 101)
        stretched = fit.trajectory.time_scaled(s)
        for r in range(4):
            np.testing.assert_allclose(scaled.trajectory(times * s, r), stretched(times * s, r), atol=1e-8)
            np.testing.assert_allclose(stretched(times * s, r), fit.trajectory(times, r) * s**-r, atol=1e-9)


@pytest.mark.parametrize("ends", ["natural", "rest"])
def test_continuity_up_to_jerk(rng: np.random.Generator, ends: str) -> None:
    t, f = knots_and_values(rng, 8, uniform=False, joints=5)
    fit = fit_septic_spline(t, f, SplineSettings(p=30.0, a=(0.1, 0.5, 1.0), ends=ends))  # type: ignore[arg-type]
    trajectory = fit.trajectory
    h = np.diff(t)
    for i in range(1, len(t) - 1):
        for r in range(4):
            left = np.polynomial.polynomial.polyval(h[i - 1], trajectory._coefficients(r)[i - 1].T)
            right = trajectory._coefficients(r)[i][:, 0]
            np.testing.assert_allclose(left, right, atol=1e-8 * (1 + np.abs(right).max()))
            np.testing.assert_allclose(right, fit.nodes[i, :, r], atol=1e-9 * (1 + np.abs(right).max()))
    if ends == "rest":
        for r in (1, 2):
            np.testing.assert_allclose(trajectory(t[[0, -1]], r), 0.0, atol=1e-12)


# --- oracle: penalised least squares in the degree-7 B-spline space, interior knots x4 ------


def bspline_oracle(
    t: np.ndarray, f: np.ndarray, p: float, a: tuple[float, float, float], ends: str, exact_ends: bool
) -> BSpline:
    k = 7
    knots = np.concatenate([[t[0]] * (k + 1), np.repeat(t[1:-1], 4), [t[-1]] * (k + 1)])
    n_basis = len(knots) - k - 1
    assert n_basis == 4 * len(t)
    basis = BSpline(knots, np.eye(n_basis), k)
    gauss, weights = np.polynomial.legendre.leggauss(8)
    penalty = np.zeros((n_basis, n_basis))
    for lo, hi in itertools.pairwise(t):
        x = lo + (hi - lo) * (gauss + 1) / 2
        w = weights * (hi - lo) / 2
        for r, weight in enumerate(a, start=1):
            if weight:
                d = basis(x, r)
                penalty += weight * (d.T * w) @ d
    at_nodes = basis(t)
    data_rows = list(range(len(t)))
    constraints, values = [], []
    if exact_ends:
        data_rows = data_rows[1:-1]
        constraints += [at_nodes[0], at_nodes[-1]]
        values += [f[0], f[-1]]
    if ends == "rest":
        for r in (1, 2):
            d = basis(t[[0, -1]], r)
            constraints += [d[0], d[1]]
            values += [np.zeros(f.shape[1])] * 2
    b = at_nodes[data_rows]
    hessian = penalty + p * b.T @ b
    gradient = p * b.T @ f[data_rows]
    m = len(constraints)
    kkt = np.zeros((n_basis + m, n_basis + m))
    kkt[:n_basis, :n_basis] = hessian
    if m:
        c = np.array(constraints)
        kkt[:n_basis, n_basis:] = c.T
        kkt[n_basis:, :n_basis] = c
    rhs = np.vstack([gradient, np.array(values).reshape(m, f.shape[1])]) if m else gradient
    solution = np.linalg.solve(kkt, rhs)[:n_basis]
    return BSpline(knots, solution, k)


@pytest.mark.parametrize(
    ("a", "ends", "exact_ends"),
    [
        ((0.2, 0.5, 1.0), "natural", False),
        ((1.0, 0.0, 0.3), "rest", True),
        ((0.0, 2.0, 1.0), "natural", True),
    ],
)
def test_mixed_weights_match_bspline_least_squares(
    rng: np.random.Generator, a: tuple[float, float, float], ends: str, exact_ends: bool
) -> None:
    t, f = knots_and_values(rng, 6, uniform=False)
    p = 40.0
    fit = fit_septic_spline(t, f, SplineSettings(p=p, a=a, ends=ends, exact_ends=exact_ends))  # type: ignore[arg-type]
    oracle = bspline_oracle(t, f, p, a, ends, exact_ends)
    times = np.linspace(t[0], t[-1], 401)
    for r in range(4):
        np.testing.assert_allclose(fit.trajectory(times, r), oracle(times, r), atol=1e-7 * 10**r)


def paper_waypoints() -> np.ndarray:
    """Start, three waypoints lifting the tool over the crate, goal (a plausible FMA answer)."""
    robot = ck.load_cpr()
    points = [PAPER_START_TCP, (0.35, 0.55, 0.50), (0.0, 0.70, 0.55), (-0.35, 0.55, 0.50), PAPER_GOAL_TCP]
    return np.array([ck.tcp_ik(robot, p) for p in points])


def test_paper_setting_node_deviation() -> None:
    waypoints = paper_waypoints()
    fit = fit_septic_spline(uniform_knots(4, 4.0), waypoints, SplineSettings(p=1e6, a=(0, 0, 1)))
    deviation_um = fit.max_node_deviation * 1e6
    print(f"\npaper setting (N = 4, h = 1 s, p = 1e6): max node deviation {deviation_um:.3f} um")
    print("(paper: 0.55 um on its own waypoints; limit 20 um)")
    assert deviation_um < 20.0
    assert np.all(fit.node_deviation[[0, -1]] == 0.0)


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"a": (0, 0, 0)}, "a = [0, 0, 0] leave the spline undetermined"),
        ({"a": (0, -1, 1)}, "a = [0, -1, 1] must be three finite numbers >= 0"),
        ({"p": 0.0}, "p = 0.0 must be > 0"),
        ({"p": -5.0}, "p = -5.0 must be > 0"),
        ({"p": float("nan")}, "p = nan must be > 0"),
        ({"ends": "clamped"}, "ends = 'clamped'; allowed: 'natural', 'rest'"),
    ],
)
def test_bad_settings(kwargs: dict[str, object], pattern: str) -> None:
    with pytest.raises(SplineError, match=re.escape(pattern)):
        SplineSettings(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("knots", "values", "settings", "pattern"),
    [
        ([0, 1, 1, 2], [0, 1, 2, 3], SplineSettings(), "t[1] = 1.0 >= t[2] = 1.0"),
        ([0, 2, 1], [0, 1, 2], SplineSettings(), "t[1] = 2.0 >= t[2] = 1.0"),
        ([0, 1, 2], [0, np.nan, 2], SplineSettings(), "must be finite numbers (no NaN or inf)"),
        (
            [0, 1],
            [0, 1],
            SplineSettings(a=(0, 0, 1)),
            "2 node(s) given; a spline whose lowest weighted derivative is order 3 needs at least 3",
        ),
        ([0], [0], SplineSettings(a=(1, 0, 0)), "1 node(s) given"),
        ([0, 1, 2], [0, 1], SplineSettings(), "do not match"),
        ([0, 1, 2], [0, 1, 2], SplineSettings(p=(1.0, 2.0)), "2 node weights p for 3 nodes"),
    ],
)
def test_bad_input(knots: list[float], values: list[float], settings: SplineSettings, pattern: str) -> None:
    with pytest.raises(SplineError, match=re.escape(pattern)):
        fit_septic_spline(knots, values, settings)


def test_per_node_weights_and_exact_nodes(rng: np.random.Generator) -> None:
    t, f = knots_and_values(rng, 4, uniform=True)
    fit = fit_septic_spline(t, f, SplineSettings(p=(1.0, INF, 1.0, 1e3, 1.0)))
    assert np.all(fit.node_deviation[[0, 1, 4]] == 0.0)  # exact node and exact ends
    assert np.abs(fit.node_deviation[2]).max() > np.abs(fit.node_deviation[3]).max()


def test_single_joint_vector_input(rng: np.random.Generator) -> None:
    t, f = knots_and_values(rng, 4, uniform=True, joints=1)
    fit = fit_septic_spline(t, f[:, 0])
    assert fit.trajectory.n_joints == 1


@pytest.mark.parametrize("segments", [5, DENSE_MAP_NODES + 3])  # dense map, then banded solves
def test_prepared_solver_reuse_and_batch(rng: np.random.Generator, segments: int) -> None:
    t, f = knots_and_values(rng, segments, uniform=False, joints=4)
    p = np.tile([INF, 10.0, 1e3, INF, 5.0, 1.0], segments)[: segments + 1]
    settings = SplineSettings(p=tuple(p), a=(0.1, 0.0, 1.0), ends="rest")
    solver = SepticSplineSolver(t, settings)
    candidates = [rng.normal(size=f.shape) for _ in range(3)]
    for values in candidates:
        one_shot = fit_septic_spline(t, values, settings)
        reused = solver.solve(values)
        np.testing.assert_array_equal(reused.nodes, one_shot.nodes)
    stacked = np.concatenate(candidates, axis=1)  # (N + 1, 3 x 4): every joint of every candidate
    batch = solver.solve_batch(stacked)
    for m, values in enumerate(candidates):
        np.testing.assert_allclose(
            batch[:, 4 * m : 4 * m + 4], solver.solve(values).trajectory.coefficients, atol=1e-12
        )
    # pinned nodes (p = inf, and the first) are met exactly, at rest at the start
    for i in np.flatnonzero(~np.isfinite(p[:-1])):
        np.testing.assert_array_equal(batch[i, :, 0], stacked[i])
    np.testing.assert_array_equal(batch[0, :, 1:3], 0.0)


def test_large_problem_uses_the_sparse_path(rng: np.random.Generator) -> None:
    # N = 400 exact interpolation: the right-hand side map is stored sparse
    t, f = knots_and_values(rng, 400, uniform=False, joints=2)
    solver = SepticSplineSolver(t, SplineSettings(p=INF))
    assert not isinstance(solver._coupling, np.ndarray)
    fit = solver.solve(f)
    reference = scipy_quintic(t, f, "natural")
    times = np.linspace(t[0], t[-1], 4001)
    np.testing.assert_allclose(fit.trajectory(times), reference(times), atol=1e-8)
