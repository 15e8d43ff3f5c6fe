"""RRT-Connect on an orientation constraint's manifold: a path that keeps it where a free path cannot be bent.

Projection-based constrained planning (as OMPL's ``ProjectedStateSpace``): every node is
a configuration projected onto the constraint (:class:`~planning.task.orientation_projection.Projector`),
and every edge is walked in steps of at most :data:`STEP_M` of robot motion (``sum_j R_j
|dq_j|``, :func:`cpr_kin.motion_radii`), each step projected and checked: it keeps the
margins plus :data:`STEP_M` (so that the motion between two steps cannot reach them), it
moves no more than twice a step from the last (the projection did not jump), and it comes
closer to where the edge aims. Two trees grow from start and goal toward uniform samples
projected onto the manifold, each extension followed by the other tree's greedy connection,
roles swapped every sample (Kuffner & LaValle 2000). The path found is shortened by random
shortcuts walked the same way. Its steps are the samples the caller joins and times.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import NoSolutionError
from planning.pipeline.deadline import Deadline
from planning.pipeline.verification import Requirements
from planning.search.rrt_trees import Tree
from planning.task.orientation_projection import Projector

FloatArray = NDArray[np.float64]

STEP_M = 0.01
"""Largest robot motion between two steps of an edge [m]."""
RANGE_M = 0.3
"""Longest extension toward a sample [m]."""
MAX_SAMPLES = 1500
"""Most samples the trees grow toward before the search gives up."""
SHORTCUTS = 100
"""Shortcuts tried on the path found."""
BATCH = 16
"""Steps projected before their clearance is checked together."""


class _Walker:
    """Walks edges on the manifold, step by step (module docstring)."""

    def __init__(
        self, world: ck.CollisionWorld, projector: Projector, required: Requirements, deadline: Deadline
    ) -> None:
        self.world, self.projector, self.deadline = world, projector, deadline
        self.weights = ck.motion_radii(world.robot)
        self.margin_m = required.margin_m + STEP_M
        self.self_margin_m = required.self_margin_m + STEP_M / 2

    def distance(self, a: FloatArray, b: FloatArray) -> float:
        return float(self.weights @ np.abs(a - b))

    def walk(self, start: FloatArray, aim: FloatArray, range_m: float = np.inf) -> list[FloatArray]:
        """The steps from ``start`` (left out) toward ``aim``, as far as they go.

        Steps are projected :data:`BATCH` at a time, then checked for clearance together; the
        walk ends where the deadline has passed.
        """
        steps: list[FloatArray] = []
        q, travelled = start, 0.0
        while self.distance(q, aim) > 1e-9 and travelled < range_m and not self.deadline.passed():
            batch, stuck, moved = self.projector.steps(
                q, aim, STEP_M, range_m - travelled, BATCH, self.weights
            )
            if not len(batch):
                break
            kept = self.world.keeps_clearance(batch, self.margin_m, self.self_margin_m, ordered=True)
            valid = int(np.argmin(kept)) if not kept.all() else len(batch)
            steps += list(batch[:valid])
            if valid < len(batch) or stuck:
                break
            q, travelled = batch[-1], travelled + moved
        return steps

    def reaches(self, steps: list[FloatArray], aim: FloatArray) -> bool:
        return bool(steps) and self.distance(steps[-1], aim) <= 1e-9


def orientation_path(
    world: ck.CollisionWorld,
    projector: Projector,
    q_start: FloatArray,
    q_goal: FloatArray,
    required: Requirements,
    rng: np.random.Generator,
    deadline: Deadline | None = None,
) -> FloatArray:
    """``(n, nq)`` the steps of a path from ``q_start`` to ``q_goal`` on the manifold (module docstring).

    ``deadline`` is asked between samples and between an edge's batches of steps
    (:meth:`~planning.pipeline.deadline.Deadline.passed`).

    Raises:
        NoSolutionError: no path within :data:`MAX_SAMPLES` samples, or by ``deadline``.
    """
    deadline = deadline or Deadline()
    walker = _Walker(world, projector, required, deadline)
    direct = walker.walk(q_start, q_goal)
    if walker.reaches(direct, q_goal):
        return np.array([q_start, *direct])
    trees = (Tree(q_start), Tree(q_goal))
    lower, upper = world.robot.limits.lower, world.robot.limits.upper
    unheld = (
        f"no path keeps '{projector.frame}' within {projector.constraint.angle_rad:.4g} rad about "
        f"{list(projector.constraint.axes)} and the margins"
    )
    for sample in range(MAX_SAMPLES):
        if deadline.passed():
            raise NoSolutionError(
                f"{unheld} by the time limit ({deadline.limit_s:g} s; RRT-Connect on the constraint "
                f"stopped after {sample} samples)"
            )
        grow, other = trees if sample % 2 == 0 else trees[::-1]
        aim, angle = projector.project(rng.uniform(lower, upper))
        if angle > projector.aim_rad:
            continue
        near = grow.nearest(aim, walker.weights)
        steps = walker.walk(grow.nodes[near], aim, RANGE_M)
        if not steps:
            continue
        for q in steps:
            near = grow.add(q, near)
        toward = other.nearest(steps[-1], walker.weights)
        joined = walker.walk(other.nodes[toward], steps[-1])
        for q in joined:
            toward = other.add(q, toward)
        if walker.reaches(joined, steps[-1]) or walker.distance(other.nodes[toward], steps[-1]) <= 1e-9:
            ends = (grow.branch(near), other.branch(toward))  # each from its node back to its root
            first, second = ends if grow is trees[0] else ends[::-1]
            return _shortened(np.concatenate([first[::-1], second[1:]]), walker, rng)
    raise NoSolutionError(f"{unheld} (RRT-Connect on the constraint, {MAX_SAMPLES} samples)")


def _shortened(path: FloatArray, walker: _Walker, rng: np.random.Generator) -> FloatArray:
    """``path`` with random pieces replaced by direct walks that reach, then its corners cut greedily."""
    for _ in range(SHORTCUTS):
        if len(path) < 3:
            break
        i, j = sorted(rng.choice(len(path), size=2, replace=False))
        if j - i < 2:
            continue
        steps = walker.walk(path[i], path[j])
        if walker.reaches(steps, path[j]) and len(steps) < j - i:
            path = np.concatenate([path[: i + 1], np.array(steps), path[j + 1 :]])
    return _greedy(path, walker)


def _greedy(path: FloatArray, walker: _Walker) -> FloatArray:
    """From each kept point, the direct walk to the farthest point of ``path`` it reaches (halving)."""
    kept, i = [path[0]], 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1:
            steps = walker.walk(path[i], path[j])
            if walker.reaches(steps, path[j]):
                break
            j = i + (j - i) // 2
        if j == i + 1:
            kept.append(path[j])
        else:
            kept += steps
        i = j
    return np.array(kept)
