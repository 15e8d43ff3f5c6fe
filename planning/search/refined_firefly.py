"""The planner's search as one :class:`~planning.search.optimizer.Optimizer`: firefly, then CMA-ES.

The firefly (:mod:`planning.search.firefly`) explores from its seeds and a random population
until its early stop; from its best, the CMA-ES refinement (:mod:`planning.search.refinement`)
descends within the rest of the evaluation budget, on the same generator. The best need not
be feasible: a seed that misses only by a little (a spline overshooting a joint limit by a
fraction of a percent, or grazing the margin) is one the firefly's random moves rarely
improve, while the refinement's small steps follow the fitness's penalty down to feasible
values; the early stop so counts stalled iterations whether the best is feasible or not.
With ``explore=False`` the best seed is refined at once: the planner asks it for a
feasible seed, whose neighbourhood the firefly's moves rarely improve, and for one that
follows a sampling planner's path, which the refinement repairs where the firefly's random
population wanders off (:func:`planning.pipeline.search.explores`, ``docs/tuning.md``).

The planner runs it on its waypoint objective, and the benchmark of peer
optimisers (``scripts/bench_peers.py``) runs the same object beside the peers, so both
measure one search.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planning.search.firefly import FireflyProgress, firefly_minimize
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import BatchObjective, SearchResult, evaluated_points
from planning.search.refinement import refine_search
from planning.search.refinement_settings import STALL_GENERATIONS, RefinementSettings

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class RefinedFirefly:
    """The firefly and, from its best, the CMA-ES refinement, as one optimiser.

    Attributes:
        firefly: the firefly's parameters; its iterations follow from the budget
            (``budget // fireflies - 1``).
        refinement: the refinement's settings; ``None``: the firefly's best as it is.
        stall_generations: the refinement's stalled generations that end it (0: to the budget).
        seeds: ``(k, d)`` points that replace the first fireflies of the initial population.
        feasible_below: the objective's bound of feasible values. Without a refinement the
            firefly's early stop counts only once its best is at or below it: an infeasible
            best keeps exploring, as nothing would repair it. With one, an infeasible best
            starts it with the refinement's ``infeasible_sigma``.
        lower_bound: about the least value the objective can take (the refinement counts
            stalls only near it); ``None``: unknown.
        progress: called after every firefly iteration, or once for the seeds when the
            firefly does not run.
        stop: asked before every firefly iteration and refinement generation; ``True`` ends
            the search with its best so far (a time limit). ``None``: never.
        explore: the firefly runs before the refinement. ``False``: the refinement starts
            from the best of the ``seeds``, feasible or not (the firefly runs without seeds
            or a refinement).
    """

    firefly: FireflySettings
    refinement: RefinementSettings | None = field(default_factory=RefinementSettings)
    stall_generations: int = STALL_GENERATIONS
    seeds: FloatArray | None = None
    feasible_below: float = math.inf
    lower_bound: float | None = None
    progress: Callable[[FireflyProgress], None] | None = None
    explore: bool = True
    stop: Callable[[], bool] | None = None

    def __call__(
        self,
        objective: BatchObjective,
        lower: FloatArray,
        upper: FloatArray,
        budget: int,
        rng: np.random.Generator,
    ) -> SearchResult:
        """Minimise ``objective`` over ``[lower, upper]`` in at most ``budget`` evaluations."""
        settings = self.firefly
        iterations = max(budget // settings.fireflies - 1, 0)
        if iterations != settings.iterations:
            settings = dataclasses.replace(settings, iterations=iterations)
        found: SearchResult | None = None
        if not self.explore and self.seeds is not None and self.refinement is not None:
            found = evaluated_points(objective, lower, upper, self.seeds)
            if self.progress is not None:  # the seeds are the search's initial population
                mean = float(found.mean_history[0])
                self.progress(FireflyProgress(0, settings.iterations, found.fitness, mean, found.evaluations))
        if found is None:
            stall_below = self.feasible_below if self.refinement is None else math.inf
            found = firefly_minimize(
                objective,
                lower,
                upper,
                settings,
                rng,
                self.progress,
                self.seeds,
                stall_below=stall_below,
                stop=self.stop,
            )
        if self.refinement is None:
            return found
        refinement = self.refinement
        if found.fitness > self.feasible_below:  # farther to go than a polish
            refinement = dataclasses.replace(refinement, sigma=refinement.infeasible_sigma)
        return refine_search(
            objective,
            lower,
            upper,
            found,
            budget - found.evaluations,
            rng,
            refinement,
            stall_generations=self.stall_generations,
            lower_bound=self.lower_bound,
            stop=self.stop,
        )
