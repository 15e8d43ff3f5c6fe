"""The search's candidates, timed and verified, best first: the planner's last word on a search.

:func:`first_verified` takes the best candidate, then the final population's others the
fitness found feasible, and returns the first whose timed trajectory passes the certified
continuous check (:mod:`planning.verification`) and the planner's node-deviation bound.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory
from planning.errors import NoTrajectoryFoundError
from planning.problem import Problem
from planning.search.optimizer import SearchResult
from planning.timing import NARROWED_ACCELERATION, Timing, narrowed_timing, timings
from planning.verification import Verification, verify_trajectory

FloatArray = NDArray[np.float64]

PREFERRED_FIRST = 3
"""How many candidates have their preferred timing verified before any falls back."""


def verify(problem: Problem, trajectory: Trajectory, fit: SplineFit) -> Verification:
    """The scene's verification, plus the node-deviation bound of the planner settings."""
    scene = problem.scene
    verification = verify_trajectory(
        problem.world, trajectory, scene.safety_margin, scene.planner.verify_step_m
    )
    bound = scene.planner.max_node_deviation
    if bound is not None and fit.max_node_deviation > bound:
        problem_text = (
            f"deviates {fit.max_node_deviation:.3g} from its nodes, more than max_node_deviation = {bound:g}"
        )
        verification = Verification(verification.check, (*verification.problems, problem_text))
    return verification


def distinct(points: list[FloatArray]) -> list[FloatArray]:
    """``points`` without repeats, in order.

    The best is also the first of a refined population: a point refused once would be timed
    and verified again.
    """
    kept: list[FloatArray] = []
    for point in points:
        if not any(np.array_equal(point, other) for other in kept):
            kept.append(point)
    return kept


def first_verified(
    problem: Problem, result: SearchResult
) -> tuple[FloatArray, FloatArray, Timing, Verification, int]:
    """The first candidate whose timed trajectory passes the verification.

    Candidates: the best, then the final population's ones the fitness found feasible (an
    infeasible one will not pass the verification), best first, each once. In order:

    1. the best's preferred (fastest) timing;
    2. the narrowed timings (:func:`~planning.timing.narrowed_timing`) of the first
       :data:`PREFERRED_FIRST`, one share of :data:`~planning.timing.NARROWED_ACCELERATION`
       after the other (each computed only when the previous share failed), each share's
       shortest first, whichever candidate they time; the first share's go with the other
       two's preferred timings: a nearly as good candidate run at full speed beats the best
       one run slower, and a worse one run at full speed does not;
    3. their other timings (the uniform ones), shortest first;
    4. each further candidate's timings, in order.

    Returns the candidate, its nodes, timing, verification and how many candidates were timed.

    Raises:
        NoTrajectoryFoundError: none passes.
    """
    objective = problem.objective
    order = np.argsort(result.population_fitness, kind="stable")
    feasible = result.population_fitness <= objective.t_max  # both fitnesses rank feasible at or below t_max
    candidates = distinct([result.x] + [result.population[k] for k in order if feasible[k]])
    timed: list[list[Timing]] = []

    def offered(k: int) -> list[Timing]:
        while len(timed) <= k:
            timed.append(timings(problem, objective.nodes(candidates[len(timed)][None])[0]))
        return timed[k]

    def shortest_first(pairs: list[tuple[int, Timing | None]]) -> list[tuple[int, Timing]]:
        found = [(k, timing) for k, timing in pairs if timing is not None]
        return sorted(found, key=lambda pair: pair[1].trajectory.duration)  # stable

    def attempts() -> Iterator[tuple[int, Timing]]:
        preferred = list(range(min(PREFERRED_FIRST, len(candidates))))
        yield 0, offered(0)[0]  # most plans end here, after one timing
        others: list[tuple[int, Timing | None]] = [(k, offered(k)[0]) for k in preferred[1:]]
        narrowing = preferred
        for share in NARROWED_ACCELERATION:  # share by share: a path that passes costs no lower share
            found = [(k, narrowed_timing(problem, offered(k), share)) for k in narrowing]
            yield from shortest_first(others + found)
            others = []
            narrowing = [k for k, timing in found if timing is not None]  # a lower share is slower still
        yield from shortest_first([(k, timing) for k in preferred for timing in offered(k)[1:]])
        yield from ((k, timing) for k in range(PREFERRED_FIRST, len(candidates)) for timing in offered(k))

    first: Verification | None = None
    for k, timing in attempts():
        verification = verify(problem, timing.trajectory, timing.fit)
        first = first or verification
        if verification.accepted:
            x = candidates[k]
            return x, objective.nodes(x[None])[0], timing, verification, len(timed)
    assert first is not None  # candidates is never empty
    raise NoTrajectoryFoundError(
        f"no collision-free trajectory found: the best candidate {'; '.join(first.problems)} "
        f"({len(candidates)} candidates verified)",
        first.check,
    )
