"""What every optimiser of :mod:`planning.search` shares: its interface and its result.

An optimiser minimises a *batch objective* (``(S, d)`` candidates in -> ``(S,)`` values
out, lower is better) over a box, within an evaluation budget, drawing randomness only from
the ``numpy.random.Generator`` it is given. The planner calls any :class:`Optimizer` the
same way (``plan(scene, optimizer=...)``), so the firefly and its baselines are compared on
one objective and one budget.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

BatchObjective = Callable[[FloatArray], FloatArray]
"""Objective over a batch: ``(S, d)`` points in the problem's units -> ``(S,)`` values."""

STALL_TOLERANCE = 1e-3
"""Relative improvement of the best value below which an iteration counts as stalled."""


def evaluate_in_box(
    objective: BatchObjective, lower: FloatArray, span: FloatArray, u: FloatArray
) -> FloatArray:
    """``objective`` at the points ``lower + u span`` of the normalised ``(S, d)`` batch ``u``.

    Raises:
        PlanningError: the objective did not return ``(S,)`` values.
    """
    values = np.asarray(objective(lower + u * span), dtype=float)
    if values.shape != (len(u),):
        raise PlanningError(
            f"objective returned shape {values.shape} for {len(u)} candidates; expected ({len(u)},)"
        )
    return values


@dataclass
class EarlyStop:
    """The searches' early stop, deterministic: stop after ``limit`` iterations in a row.

    An iteration stalls when it leaves the best value less than a relative
    :data:`STALL_TOLERANCE` below :attr:`reference`; ``limit`` 0: never stop.
    """

    limit: int
    reference: float
    """The best value when the count last started."""
    stalled: int = 0

    def update(self, best: float, counts: bool = True) -> bool:
        """Count an iteration that ended with ``best``; ``True``: stop now.

        ``counts=False`` (e.g. no feasible value yet) restarts the count as an improvement does.
        """
        if best < self.reference - STALL_TOLERANCE * abs(self.reference) or not counts:
            self.stalled, self.reference = 0, best
            return False
        self.stalled += 1
        return self.stalled == self.limit


@dataclass(frozen=True)
class SearchResult:
    """Outcome of an optimiser run.

    Attributes:
        x: best point found, in the problem's units.
        fitness: its objective value.
        evaluations: objective evaluations (candidates, not calls).
        best_history: ``(T + 1,)`` best value after each iteration (0: initial population).
        mean_history: ``(T + 1,)`` population mean after each iteration.
        evaluation_history: ``(T + 1,)`` cumulative evaluations after each iteration.
        population: ``(n, d)`` final positions, in the problem's units.
        population_fitness: ``(n,)`` their values.
    """

    x: FloatArray
    fitness: float
    evaluations: int
    best_history: FloatArray
    mean_history: FloatArray
    evaluation_history: NDArray[np.int64]
    population: FloatArray
    population_fitness: FloatArray

    @classmethod
    def of_point(cls, x: FloatArray, fitness: float, evaluations: int) -> SearchResult:
        """A search that ends at the single point ``x`` of value ``fitness`` after ``evaluations``."""
        value = np.array([fitness])
        return cls(
            x=x,
            fitness=fitness,
            evaluations=evaluations,
            best_history=value,
            mean_history=value,
            evaluation_history=np.array([evaluations], dtype=np.int64),
            population=x[None],
            population_fitness=value,
        )


@dataclass
class History:
    """A search's record after each iteration (or batch), in the unit box ``[0, 1]^d``.

    One entry per :meth:`record`: the best value so far, the mean of the values just
    evaluated, and the evaluations so far; :meth:`result` turns it into a
    :class:`SearchResult` in the problem's units.
    """

    best: list[float] = field(default_factory=list)
    mean: list[float] = field(default_factory=list)
    evaluations: list[int] = field(default_factory=list)

    def record(self, best: float, mean: float, evaluations: int) -> None:
        """Append one iteration's best value, mean value and evaluations so far."""
        self.best.append(best)
        self.mean.append(mean)
        self.evaluations.append(evaluations)

    def result(
        self,
        lower: FloatArray,
        span: FloatArray,
        best_u: FloatArray,
        best_f: float,
        population_u: FloatArray,
        population_f: FloatArray,
    ) -> SearchResult:
        """The search's result: best point ``lower + best_u span``, the final population likewise.

        Its evaluations are the last recorded count (0 if nothing was recorded).
        """
        return SearchResult(
            x=lower + best_u * span,
            fitness=best_f,
            evaluations=self.evaluations[-1] if self.evaluations else 0,
            best_history=np.array(self.best),
            mean_history=np.array(self.mean),
            evaluation_history=np.array(self.evaluations, dtype=np.int64),
            population=lower + population_u * span,
            population_fitness=np.asarray(population_f, dtype=float),
        )


class Optimizer(Protocol):
    """A box-constrained batch optimiser with an evaluation budget."""

    def __call__(
        self,
        objective: BatchObjective,
        lower: FloatArray,
        upper: FloatArray,
        budget: int,
        rng: np.random.Generator,
    ) -> SearchResult:
        """Minimise ``objective`` over ``[lower, upper]`` in at most ``budget`` evaluations."""
        ...


def evaluated_points(
    objective: BatchObjective, lower: ArrayLike, upper: ArrayLike, points: ArrayLike
) -> SearchResult:
    """``points`` ``(k, d)`` of the box evaluated in one batch, as a search's result.

    The best of them is its point, all of them its population (best first); one history
    entry.

    Raises:
        PlanningError: ``points`` is not a non-empty ``(k, d)`` batch of the box.
    """
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    given = np.asarray(points, dtype=float)
    if (
        given.ndim != 2
        or len(given) == 0
        or given.shape[1:] != lo.shape
        or not np.all((given >= lo) & (given <= hi))
    ):
        raise PlanningError(
            f"points of shape {given.shape} must be k >= 1 points of the box, {lo.shape} each"
        )
    span = hi - lo
    u = (given - lo) / span
    values = evaluate_in_box(objective, lo, span, u)
    order = np.argsort(values, kind="stable")
    history = History()
    history.record(float(values[order[0]]), float(np.mean(values)), len(values))
    return history.result(lo, span, u[order[0]], float(values[order[0]]), u[order], values[order])
