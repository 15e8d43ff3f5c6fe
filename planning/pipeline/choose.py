"""The choice stage: the search's candidates, timed and verified, best first; the first that passes.

:func:`choose` takes the best candidate, then the final population's others the fitness
found feasible (an infeasible one will not pass the verification), best first, each once,
and returns the first whose timed trajectory passes the certified continuous check
(:mod:`planning.pipeline.verification`) and the planner's node-deviation bound, as a
:class:`Choice`; or a :class:`Refusal` saying why the best one failed. In order:

1. the best's preferred (fastest) timing;
2. the preferred timings of the next candidates up to ``preferred_first``, in the search's
   order, each timed only when the one before failed: the refinement's population is
   nearly as good as its best, and such a candidate run at full speed is shorter than the
   best run slower, or longer by a few per cent, for a fraction of the narrowed timings'
   cost (``docs/tuning.md``). Among these first ``preferred_first``, those whose path the
   fastest timing's moving averages are foreseen to bring inside the clearance
   (:func:`foreseen_clear`) come after the others: their fastest timing would most often
   fail the check, after costing a timing and a verification (unless the best is
   infeasible, whose check says why no candidate passes, or the time limit has passed);
3. the narrowed timings (:meth:`~planning.pipeline.timing.FreeDuration.narrowed`) of those
   first ``preferred_first``, one share of ``narrowed_acceleration`` after the other (each
   computed only when the previous share failed), each share's shortest first, whichever
   candidate they time;
4. their other timings (the uniform ones), shortest first;
5. each further candidate's timings, in order.

Each candidate is timed once, however often the search returns it. A best candidate that
comes deeper inside the margin than one verification step at one of its samples
(:func:`beyond_margin`) is verified in its first timing only: every timing follows its path;
and past the deadline not at all (its check would only say why it fails: the refusal names
the deepest sample instead).
Once the problem's deadline has passed, no further timing is tried after one that failed:
past its time limit a plan verifies only the timing in hand (the best's first, at least),
and a certified check still under way where the deadline cuts it stops there, refused
(:mod:`planning.pipeline.deadline`). With a feasible best, the deadline is a search's that
found one (:attr:`~planning.pipeline.deadline.Deadline.feasible_at_s`: on the hulls, the plan's own).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory
from planning.errors import NoTrajectoryFoundError
from planning.pipeline.objective import Breakdown
from planning.pipeline.offered import Offered, Timing
from planning.pipeline.problem import Problem
from planning.pipeline.verification import Requirements, Verification, unchecked, verify_trajectory
from planning.search.optimizer import SearchResult

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Choice:
    """The candidate whose timed trajectory passed the verification.

    Attributes:
        x: its decision vector.
        nodes: ``(p + 2, nq)`` start, waypoints and goal [rad, m].
        timing: the timing that passed.
        verification: its verification (accepted).
        candidates_timed: how many candidates were timed to find it.
    """

    x: FloatArray
    nodes: FloatArray
    timing: Timing
    verification: Verification
    candidates_timed: int

    accepted = True


@dataclass(frozen=True)
class Refusal:
    """No candidate passed: why the best one failed.

    Attributes:
        cause: why the best candidate failed, one sentence for the user.
        check: the best candidate's certified continuous check.
        verified: how many candidates were verified, e.g. ``"3 candidates verified"``.
    """

    cause: str
    check: ck.CurveCheck
    verified: str = ""

    accepted = False

    def error(self, *tried: str) -> NoTrajectoryFoundError:
        """The error a planner raises when this was its last word; ``tried``: what else it tried."""
        said = "; ".join(part for part in (self.verified, *tried) if part)
        return NoTrajectoryFoundError(
            f"no collision-free trajectory found{f' ({said})' if said else ''}: {self.cause}", self.check
        )


def verify(problem: Problem, trajectory: Trajectory, fit: SplineFit) -> Verification:
    """The scene's verification, plus the node-deviation bound of the planner settings.

    Its certified checks stop where the problem's deadline cuts them
    (:meth:`~planning.pipeline.deadline.Deadline.cut`).
    """
    scene = problem.scene
    verification = verify_trajectory(
        problem.world, trajectory, Requirements.of(problem), stop=problem.deadline.stop
    )
    bound = scene.planner.max_node_deviation
    if bound is not None and fit.max_node_deviation > bound:
        problem_text = (
            f"deviates {fit.max_node_deviation:.3g} from its nodes, more than max_node_deviation = {bound:g}"
        )
        verification = Verification(
            verification.check, (*verification.problems, problem_text), verification.torques
        )
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


def infeasibility(breakdown: Breakdown, problem: Problem, besides_check: bool = False) -> str:
    """Why a candidate is infeasible, from its terms (one candidate), in a few words.

    With ``besides_check``, only what the certified check's own words do not say (the fixed
    duration's limits); the clearance, the joint ranges and the node deviation they state.
    """
    reasons = []
    if breakdown.limit_excess[0] > 0:
        excess, seconds = breakdown.limit_excess[0], problem.scene.duration
        reasons.append(
            f"limits exceeded by {excess:.0%} in {seconds:g} s (lengthen duration or leave it out)"
        )
    if besides_check:
        return ", ".join(reasons)
    if breakdown.depth_m[0] > 0:
        reasons.append(f"inside the {problem.objective.required_m:.3g} m the search asks")  # margin + step
    if breakdown.overshoot[0] > 0:
        reasons.append(f"{100 * breakdown.overshoot[0]:.2g} % of a joint range beyond it")
    bound = problem.scene.planner.max_node_deviation
    if bound is not None and breakdown.node_deviation[0] > bound:
        reasons.append(f"node deviation {breakdown.node_deviation[0]:.3g} > {bound:g}")
    return ", ".join(reasons) or "infeasible"


def beyond_margin(problem: Problem, searched: SearchResult) -> str | None:
    """Where the search's best is infeasible and, at one of its samples, deeper inside a margin than a step.

    The fitness asks ``safety_margin + verify_step_m`` at its samples, and a candidate short
    of that only within the step may still pass the certified check, which asks the margin.
    One whose path comes more than ``verify_step_m`` inside the margin at one of its samples
    (from an obstacle, or inside the self margin from its own links) cannot: each of its
    timings follows that path to within the millimetres its moving averages cut off bends.
    All the samples count, also those the fitness left unchecked once the candidate was
    infeasible (:meth:`~planning.pipeline.objective.WaypointObjective.breakdown`). Returns
    the deepest such sample's pair and distance in words, ``None`` where none is that deep.
    """
    objective, scene, world = problem.objective, problem.scene, problem.world
    if objective.feasible(searched.fitness):
        return None
    paths = objective.paths(objective.nodes(searched.x[None]))
    samples = objective.checked_configurations(paths.samples[0])
    step = scene.planner.verify_step_m
    inside, pairs = world.min_clearance_batch(samples, below_m=scene.safety_margin - step)
    if np.isfinite(inside).any():
        k = int(np.argmin(inside))
        part, obstacle = world.pairs[int(pairs[k])][:2]
        return f"{part} to '{obstacle}' {inside[k]:.3f} m at a sample of its path"
    if not world.self_collision:
        return None
    own, own_pairs = world.self_collision.distances(samples)
    k = int(np.argmin(own))
    if own[k] >= scene.self_margin - step:
        return None
    first, second = world.self_collision.pairs[int(own_pairs[k])]
    return f"{first} to {second} {own[k]:.3f} m at a sample of its path (self margin {scene.self_margin:g} m)"


def foreseen_clear(problem: Problem, candidates: FloatArray) -> BoolArray:
    """``(S,)`` whether each candidate's path keeps the clearance where the timing's averages take it.

    The path's samples moved as :meth:`~planning.pipeline.path_terms.SplinePaths.averaged`
    foresees (:mod:`planning.curves.averaged_path`), checked as the fitness checks its
    samples but with only the tuning's ``foresight_step_share`` of the verification step
    beyond the margin (and of the self step beyond the self margin): the foreseen samples
    are those of the uncapped profile and miss the motion between them, so the whole step
    would foresee cuts the timing does not make (``docs/tuning.md``). ``True`` where
    nothing is foreseen: a fixed duration (its timing is the candidate's own),
    point-to-point paths, a torque-limited estimate.
    """
    objective, settings = problem.objective, problem.scene.planner
    short_of = 1.0 - settings.tuning.foresight_step_share
    clear = np.ones(len(candidates), dtype=bool)
    if not objective.estimates_duration:
        return clear
    samples = objective.paths(objective.nodes(candidates)).samples
    moved = objective.paths.averaged(samples)
    if moved is None:
        return clear
    configurations = objective.checked_configurations(moved).reshape(-1, samples.shape[2])
    keeps = problem.world.keeps_clearance(
        configurations,
        objective.required_m - short_of * settings.verify_step_m,
        objective.required_self_m - short_of * settings.self_step_m,
    )
    return np.asarray(keeps.reshape(len(candidates), -1).all(axis=1))


def choose(problem: Problem, searched: SearchResult, deepest: str | None) -> Choice | Refusal:
    """The first candidate whose timing passes (module docstring); ``deepest``: :func:`beyond_margin`'s."""
    objective = problem.objective
    order = np.argsort(searched.population_fitness, kind="stable")
    feasible = objective.feasible(searched.population_fitness)
    candidates = distinct([searched.x] + [searched.population[k] for k in order if feasible[k]])
    timed: dict[int, Offered] = {}
    verified: dict[int, Verification] = {}  # each candidate's first verification
    if deepest is not None and problem.deadline.passed():  # its check would only say why it fails
        why = infeasibility(objective.breakdown(searched.x[None]), problem)
        cause = f"no candidate was feasible; the best: {deepest}, {why}"
        return Refusal(cause, unchecked(problem.scene.safety_margin, problem.scene.planner.verify_step_m))
    # an infeasible best is verified first, whatever its foresight: its check says why
    has_feasible = bool(objective.feasible(searched.fitness))
    foresee = has_feasible and not problem.deadline.passed(feasible=has_feasible)
    for k, timing in _attempts(problem, candidates, timed, foresee):
        verification = verify(problem, timing.trajectory, timing.fit)
        verified.setdefault(k, verification)
        if verification.accepted:
            x = candidates[k]
            return Choice(x, objective.nodes(x[None])[0], timing, verification, len(timed))
        if deepest is not None or problem.deadline.passed(feasible=has_feasible):
            break  # its other timings follow the same path; or time is up
    first = verified.get(0) or next(iter(verified.values()))  # candidates is never empty
    found = f"the best candidate {'; '.join(first.problems)}"
    if 0 not in verified:  # time ran out after a candidate foreseen clear
        found = f"the candidate verified {'; '.join(first.problems)}"
    if not objective.feasible(searched.fitness):  # the cause comes first, the pair named
        breakdown, check = objective.breakdown(searched.x[None]), first.check
        if check.worst_pair is not None and check.certified_min_m < check.margin_m:  # an obstacle
            closest = f"{check.worst_pair[0]} to '{check.worst_pair[1]}' {check.certified_min_m:.3f} m"
            why = infeasibility(breakdown, problem)
            found = f"no candidate was feasible; the best: {closest} certified, {why}"
        else:  # its own links, a joint range: the check's words, and what they do not say
            besides = infeasibility(breakdown, problem, besides_check=True)
            said_of_it = "; ".join(first.problems)
            found = f"no candidate was feasible{f': {besides}' if besides else ''}; the best {said_of_it}"
    said = f"{len(verified)} candidate{'' if len(verified) == 1 else 's'} verified"
    return Refusal(found, first.check, said)


def _attempts(
    problem: Problem, candidates: list[FloatArray], timed: dict[int, Offered], foresee: bool
) -> Iterator[tuple[int, Timing]]:
    """``(candidate, timing)`` in the module docstring's order; ``timed`` fills as they are timed.

    ``foresee``: the first candidates' fastest timings foreseen to be cut come after the others'.
    """
    tuning, duration, objective = problem.scene.planner.tuning, problem.duration, problem.objective

    def offered(k: int) -> Offered:
        if k not in timed:
            timed[k] = duration.timings(problem, objective.nodes(candidates[k][None])[0])
        return timed[k]

    def shortest_first(pairs: list[tuple[int, Timing | None]]) -> list[tuple[int, Timing]]:
        found = [(k, timing) for k, timing in pairs if timing is not None]
        return sorted(found, key=lambda pair: pair[1].trajectory.duration)  # stable

    preferred = list(range(min(tuning.preferred_first, len(candidates))))
    foreseen_cut: list[int] = []
    for k in preferred:  # most plans end at the first, after one timing
        if not foresee or foreseen_clear(problem, candidates[k][None])[0]:
            yield k, offered(k).first
        else:
            foreseen_cut.append(k)
    for k in foreseen_cut:
        yield k, offered(k).first
    narrowing = preferred
    for share in tuning.narrowed_acceleration:  # share by share: a path that passes costs no lower share
        found = [(k, duration.narrowed(problem, offered(k), share)) for k in narrowing]
        yield from shortest_first(found)
        narrowing = [k for k, timing in found if timing is not None]  # a lower share is slower still
    yield from shortest_first([(k, timing) for k in preferred for timing in offered(k).others])
    yield from ((k, timing) for k in range(len(preferred), len(candidates)) for timing in offered(k).all)
