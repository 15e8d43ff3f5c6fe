"""Firefly algorithm (Yang 2010; paper eq. 1-2) for batch objectives over box bounds.

The search runs in normalised coordinates ``u in [0, 1]^d`` mapped to the bounds before
every evaluation, so distances and ``gamma`` mean the same whatever the units of the
variables. A firefly ``i`` moves towards a brighter (lower objective) firefly ``j`` by

    u_i += beta0 exp(-gamma r_ij^2) (u_j - u_i) + alpha (eps - 0.5),   eps ~ U[0, 1)^d,

(the paper prints eq. 2 with a sign typo and without gamma) and is clipped to the bounds.
``alpha`` decays geometrically, ``alpha <- theta alpha``, at the start of every iteration.
With ``stall_iterations`` set, the search ends once that many iterations in a row have
improved the best value by less than a relative :data:`~planning.search.optimizer.STALL_TOLERANCE`.

Two modes:

- ``sweep`` (Yang's reference code): brightness and attractor positions are taken at the
  start of the sweep, every firefly accumulates its moves towards all brighter ones, then
  all are evaluated in one batch call: ``n (T + 1)`` evaluations. The brightest does not
  move, so the best value never gets worse.
- ``sequential`` (NiaPy's ``FireflyAlgorithm``): for every pair with ``f_i >= f_j``,
  including ``i = j``, firefly ``i`` moves and is re-evaluated at once; same random
  draws, same order, same results as NiaPy for the same seed. About ``n^2 T / 2``
  evaluations, one candidate per call.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.compiled import njit
from planning.errors import PlanningError
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import BatchObjective, EarlyStop, History, SearchResult, evaluate_in_box

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class FireflyProgress:
    """What the optional callback receives after each iteration (0: the initial population)."""

    iteration: int
    iterations: int
    best: float
    mean: float
    evaluations: int


def firefly_minimize(
    objective: BatchObjective,
    lower: ArrayLike,
    upper: ArrayLike,
    settings: FireflySettings | None = None,
    rng: np.random.Generator | int | None = 0,
    callback: Callable[[FireflyProgress], None] | None = None,
    seeds: ArrayLike | None = None,
    stall_below: float = np.inf,
    stop: Callable[[], bool] | None = None,
) -> SearchResult:
    """Minimise ``objective`` over the box ``[lower, upper]`` with the firefly algorithm.

    Args:
        objective: batch objective ``(S, d) -> (S,)``; every point passed lies in the box.
        lower: ``(d,)`` lower bounds.
        upper: ``(d,)`` upper bounds, each > the lower one.
        settings: algorithm parameters (default: the paper's, sweep mode).
        rng: a ``numpy.random.Generator`` or a seed; the same seed gives the same run.
        callback: called with a :class:`FireflyProgress` after every iteration.
        seeds: ``(k, d)`` points (in the box) that replace the first ``k`` fireflies of the
            random initial population; the random draws are the same with or without them.
        stall_below: the early stop (``settings.stall_iterations``) counts an iteration as
            stalled only while the best value is at or below this (e.g. the objective's
            bound of feasible values: an infeasible best keeps searching).
        stop: asked before every iteration; ``True`` ends the search with its best so far
            (a time limit). ``None``: never.
    """
    settings = settings or FireflySettings()
    lo = np.asarray(lower, dtype=float)
    hi = np.asarray(upper, dtype=float)
    if lo.ndim != 1 or lo.shape != hi.shape or lo.size == 0:
        raise PlanningError(f"bounds of shapes {lo.shape} and {hi.shape}; expected two (d,) arrays, d >= 1")
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(hi > lo)):
        raise PlanningError(f"bounds [{lo.tolist()}, {hi.tolist()}] must be finite with upper > lower")
    generator = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    span = hi - lo
    n, d = settings.fireflies, lo.size

    def evaluate(u: FloatArray) -> FloatArray:
        return evaluate_in_box(objective, lo, span, u)

    # NiaPy draws the initial population as uniform(lower, upper) in its (here: unit) box
    u = generator.uniform(np.zeros(d), np.ones(d), (n, d))
    if seeds is not None:
        given = np.atleast_2d(np.asarray(seeds, dtype=float))
        if given.shape[1:] != (d,) or len(given) > n or not np.all((given >= lo) & (given <= hi)):
            raise PlanningError(
                f"seeds of shape {given.shape} must be at most {n} points of the box, ({d},) each"
            )
        u[: len(given)] = (given - lo) / span
    f = evaluate(u)
    best_u, best_f = u[int(np.argmin(f))].copy(), float(np.min(f))
    evaluations = n
    history = History()
    history.record(best_f, float(np.mean(f)), evaluations)
    if callback is not None:
        callback(FireflyProgress(0, settings.iterations, best_f, history.mean[0], evaluations))
    alpha = settings.alpha
    early_stop = EarlyStop(settings.stall_iterations, best_f)
    for iteration in range(1, settings.iterations + 1):
        if stop is not None and stop():
            break
        alpha *= settings.theta
        if settings.mode == "sweep":
            u = _sweep(u, f, alpha, settings, generator)
            f = evaluate(u)
            evaluations += n
            k = int(np.argmin(f))
            if f[k] <= best_f:
                best_u, best_f = u[k].copy(), float(f[k])
        else:
            for i in range(n):
                for j in range(n):
                    if f[i] >= f[j]:
                        r = np.sqrt(np.sum((u[i] - u[j]) ** 2))
                        beta = settings.beta0 * np.exp(-settings.gamma * r**2)
                        steps = alpha * (generator.random(d) - 0.5)
                        u[i] += beta * (u[j] - u[i]) + steps
                        u[i] = np.clip(u[i], 0.0, 1.0)
                        f[i] = evaluate(u[i : i + 1])[0]
                        evaluations += 1
                        if f[i] <= best_f:
                            best_u, best_f = u[i].copy(), float(f[i])
        history.record(best_f, float(np.mean(f)), evaluations)
        if callback is not None:
            callback(FireflyProgress(iteration, settings.iterations, best_f, history.mean[-1], evaluations))
        if early_stop.update(best_f, counts=best_f <= stall_below):
            break
    return history.result(lo, span, best_u, best_f, u, f.copy())


def _sweep(
    u: FloatArray, f: FloatArray, alpha: float, settings: FireflySettings, rng: np.random.Generator
) -> FloatArray:
    """One synchronous sweep: every firefly moves towards each brighter one, in order.

    The kicks are drawn here, one ``(n, d)`` block per attractor for everyone (draws for
    a dimmer attractor are discarded), so a seed gives the same run whatever computes the
    moves; the O(n^2 d) moves themselves run compiled (:func:`_move`).
    """
    n, d = u.shape
    kicks = rng.random((n, n, d))
    moved = np.empty_like(u)
    _move(u, f, kicks, alpha, settings.beta0, settings.gamma, moved)
    return moved


@njit
def _move(
    u: FloatArray,
    f: FloatArray,
    kicks: FloatArray,
    alpha: float,
    beta0: float,
    gamma: float,
    moved: FloatArray,
) -> None:
    """Write the swept positions of fireflies ``u`` ``(n, d)`` with values ``f`` into ``moved``.

    Attractors stay where the sweep found them (``u``); firefly ``i`` moves towards every
    ``j`` with ``f[j] < f[i]`` in the order of ``j``, by ``beta0 exp(-gamma r^2)`` of the way
    plus ``alpha (kicks[j, i] - 0.5)``, and ends clipped to ``[0, 1]``.
    """
    n, d = u.shape
    for i in range(n):
        for k in range(d):
            moved[i, k] = u[i, k]
    for j in range(n):
        for i in range(n):
            if f[j] < f[i]:
                distance2 = 0.0
                for k in range(d):
                    step = u[j, k] - moved[i, k]
                    distance2 += step * step
                beta = beta0 * np.exp(-gamma * distance2)
                for k in range(d):
                    moved[i, k] += (u[j, k] - moved[i, k]) * beta + (kicks[j, i, k] - 0.5) * alpha
    for i in range(n):
        for k in range(d):
            moved[i, k] = min(max(moved[i, k], 0.0), 1.0)
