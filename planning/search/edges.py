"""Straight edges between configurations: their validity, checked in batches, and path shortening.

A sampling planner spends most of its time asking whether straight edges are valid. Here
an edge is checked as OMPL checks a motion, at configurations a fixed robot motion apart
(``resolution_m``, a motion bound ``sum_j R_j |dq_j|`` [m] with per-joint weights), but in
at most two batched calls of the validity check, which is what makes it fast in Python: a
coarse pass (the edge's first configurations and every few), then the rest of the edge up
to where the coarse pass found it blocked (OMPL stops at a motion's first invalid state in
the same spirit). The same checks shorten a found path: random shortcuts (a straight edge
between two points on it replaces what lies between when it is valid, both its ends
included: a point of an edge between two of its checked configurations was never checked
itself), then skipping vertices (from each vertex straight to the farthest one it sees),
then, given the joints' speeds, straightening one joint at a time where that makes the path
faster (:func:`straighten_joints`), then dropping collinear vertices. A validity may carry a
cheaper, looser screen (:class:`ScreenedValidity`) that a planner's trees grow on.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
Validity = Callable[[FloatArray], BoolArray]
"""``(N, d) -> (N,)``: whether each configuration is valid (clear of the margin), in order.

Exact up to the first invalid configuration; after it, a check may report any value (an
edge is known by where it is first blocked, so a check may stop there)."""


@dataclass(frozen=True)
class ScreenedValidity:
    """A validity check with a cheaper screen that a sampling planner's trees may grow on.

    Called, it is ``valid``. ``screen`` accepts every configuration ``valid`` accepts and costs
    less (the obstacles without the robot's own pairs): trees grown on it are thrown away
    mostly, so RRT-Connect grows them on the screen and holds the path they find under
    ``valid`` (:mod:`planning.search.rrt_connect`).

    Attributes:
        valid: the check a path must pass.
        screen: the cheaper, looser check.
    """

    valid: Validity
    screen: Validity

    def __call__(self, q: FloatArray) -> BoolArray:
        """``(N,)`` whether each of ``q`` ``(N, d)`` is valid (``valid``'s answer)."""
        return self.valid(q)


def screen_of(valid: Validity) -> Validity | None:
    """``valid``'s screen where it has one (:class:`ScreenedValidity`), else ``None``."""
    return valid.screen if isinstance(valid, ScreenedValidity) else None


COARSE_STRIDE = 8
"""Configurations an edge's coarse pass steps over (:meth:`Edges.free_fraction`)."""
HEAD = 2
"""An edge's first configurations, checked in its coarse pass: most edges a tree tries start
at a node that stopped against an obstacle and are blocked at once (of the edges of
:data:`WHOLE_BELOW` configurations and more: UR5 68 %, Panda 51 %, the CPR 90 %, on
MotionBenchMaker's and generated narrow scenes), and are then known from the first call,
not the second (``docs/tuning.md``)."""
STRAIGHTENED_GAIN = 1e-3
"""Least share of a piece's time a straightened joint must save to be checked (:func:`straighten_joints`)."""
WHOLE_BELOW = 48
"""Edges of fewer configurations are checked whole in the first pass: a second call of the
validity check would cost more than it saves (a 5-joint arm's edges have 16-100; a 6- or
7-joint arm's, whose joints move points farther, 60 and more; ``docs/tuning.md``)."""


class Edges:
    """Validity of straight edges, one edge a call, coarse to fine; counts the configurations checked."""

    def __init__(self, valid: Validity, weights: FloatArray, resolution_m: float) -> None:
        self.valid, self.weights, self.resolution_m, self.checks = valid, weights, resolution_m, 0

    def free_fraction(self, a: FloatArray, b: FloatArray) -> float:
        """The fraction of the edge ``a -> b`` valid from ``a`` on, in [0, 1] (``a`` assumed valid).

        Its configurations every ``resolution_m`` (the last one ``b``), in at most two calls
        of the validity check: an edge of fewer than :data:`WHOLE_BELOW` whole; a longer one
        its first :data:`HEAD` and every :data:`COARSE_STRIDE`-th (and ``b``) first, then
        the others up to the first invalid one of those: an edge that hits an obstacle is
        not checked beyond it. The answer is that of checking every configuration.
        """
        ok = self._checked(edge_points(a, b, self.weights, self.resolution_m))
        blocked = int(ok.argmin())  # the first invalid one, or 0 where all are valid
        return blocked / len(ok) if not ok[blocked] else 1.0

    def free_between(self, a: FloatArray, b: FloatArray) -> bool:
        """Whether the edge ``a -> b`` is valid, ``a`` included (a point of another edge, unchecked).

        Checked as :meth:`free_fraction` checks an edge, with ``a`` among the first.
        """
        return bool(
            self._checked(np.concatenate([a[None], edge_points(a, b, self.weights, self.resolution_m)])).all()
        )

    def chain_free(self, path: FloatArray) -> bool:
        """Whether every edge of the polyline ``path`` is valid (``path[0]`` assumed valid).

        All its edges' configurations in at most two calls of the validity check, coarse to
        fine as :meth:`free_fraction` checks one edge.
        """
        points = np.concatenate(
            [edge_points(a, b, self.weights, self.resolution_m) for a, b in itertools.pairwise(path)]
        )
        return bool(self._checked(points).all())

    def _checked(self, points: FloatArray) -> BoolArray:
        """The validity of a motion's ``points``, exact up to the first invalid one.

        Fewer than :data:`WHOLE_BELOW` in one call, more coarse to fine (:meth:`free_fraction`).
        """
        if len(points) < WHOLE_BELOW:
            self.checks += len(points)
            return self.valid(points)
        return self._coarse_to_fine(points)

    def _coarse_to_fine(self, points: FloatArray) -> BoolArray:
        """The validity of ``points``, checked up to the first invalid one (:meth:`free_fraction`)."""
        count = len(points)
        coarse = np.zeros(count, dtype=bool)
        coarse[:HEAD] = True
        coarse[COARSE_STRIDE - 1 :: COARSE_STRIDE] = True
        coarse[-1] = True
        ok = np.ones(count, dtype=bool)
        ok[coarse] = self.valid(points[coarse])
        self.checks += int(np.count_nonzero(coarse))
        rest = ~coarse
        blocked = np.flatnonzero(~ok)
        if blocked.size:
            rest[blocked[0] :] = False  # nothing past the first invalid coarse one matters
        if rest.any():
            ok[rest] = self.valid(points[rest])
            self.checks += int(np.count_nonzero(rest))
        return ok


@njit
def edge_points(a: FloatArray, b: FloatArray, weights: FloatArray, resolution_m: float) -> FloatArray:
    """``(count, d)`` the configurations of the edge ``a -> b`` every ``resolution_m``, ``b`` last.

    ``count`` spans the edge's motion bound ``sum_j w_j |b_j - a_j|`` [m] in steps of at most
    ``resolution_m`` (at least one). Compiled: a sampling planner builds one or two a sample.
    """
    length = 0.0
    for j in range(len(a)):
        length += abs(b[j] - a[j]) * weights[j]
    count = max(1, math.ceil(length / resolution_m))
    points = np.empty((count, len(a)))
    for k in range(count):
        share = (k + 1) / count
        for j in range(len(a)):
            points[k, j] = a[j] + share * (b[j] - a[j])
    return points


def shortcut(
    path: FloatArray,
    edges: Edges,
    rng: np.random.Generator,
    attempts: int,
    *,
    joint_attempts: int = 0,
    speeds: FloatArray | None = None,
) -> FloatArray:
    """Shorten ``path`` by ``attempts`` random shortcuts between points on its edges.

    Then its vertices skipped where a later one is in sight and, with the joints' ``speeds``
    [joint units/s], ``joint_attempts`` single joints straightened (:func:`straighten_joints`).
    """
    for _ in range(attempts):
        if len(path) < 3:
            break
        lengths = np.abs(np.diff(path, axis=0)) @ edges.weights
        arc = np.concatenate([[0.0], np.cumsum(lengths)])
        s0, s1 = np.sort(rng.uniform(0.0, arc[-1], 2))
        i, j = (int(np.searchsorted(arc, s, side="right")) - 1 for s in (s0, s1))
        if i == j:
            continue
        a = path[i] + (s0 - arc[i]) / max(lengths[i], 1e-300) * (path[i + 1] - path[i])
        b = path[j] + (s1 - arc[j]) / max(lengths[j], 1e-300) * (path[j + 1] - path[j])
        if edges.free_between(a, b):  # a lies between two checked configurations of its edge
            path = np.concatenate([path[: i + 1], [a, b], path[j + 1 :]])
    path = _skip_vertices(path, edges)
    if speeds is not None:
        path = straighten_joints(path, edges, speeds, rng, joint_attempts)
    return _drop_collinear(path)


def path_time(path: FloatArray, speeds: FloatArray) -> float:
    """``path``'s time at the joints' ``speeds`` [s]: each edge as long as its slowest joint takes."""
    return float((np.abs(np.diff(path, axis=0)) / speeds).max(axis=1, initial=0.0).sum())


def straighten_joints(
    path: FloatArray, edges: Edges, speeds: FloatArray, rng: np.random.Generator, attempts: int
) -> FloatArray:
    """``path`` with single joints straightened between two of its vertices where that makes it faster.

    A partial shortcut (Geraerts and Overmars 2007; OMPL's ``partialShortcutPath``), for the
    joint that wanders where the others go straight (a sampling planner's path moves every
    joint at random, a slow one as far as a fast one). Each attempt draws two vertices at
    least two apart and one joint, by the time its wandering between them costs (its travel
    beyond the straight move, over its speed [joint units/s]); between the two, that joint
    moves straight, in step with the other joints' motion, and the others keep their values.
    The change is kept where it shortens :func:`path_time` by more than
    :data:`STRAIGHTENED_GAIN` and every changed edge is valid; only such a change costs
    checks. The ends and the vertex count stay.
    """
    for _ in range(attempts):
        if len(path) < 3:
            break
        i, j = sorted(int(v) for v in rng.choice(len(path), 2, replace=False))
        if j - i < 2:
            continue
        piece = path[i : j + 1]
        steps = np.abs(np.diff(piece, axis=0))
        wander_s = np.maximum(steps.sum(axis=0) - np.abs(piece[-1] - piece[0]), 0.0) / speeds
        if wander_s.max() <= 0.0:
            continue
        k = int(rng.choice(len(speeds), p=wander_s / wander_s.sum()))
        others = np.delete(steps, k, axis=1) @ np.delete(edges.weights, k)
        arc = np.concatenate([[0.0], np.cumsum(others)])
        share = arc / arc[-1] if arc[-1] > 0.0 else np.linspace(0.0, 1.0, len(piece))
        straightened = piece.copy()
        straightened[1:-1, k] = piece[0, k] + share[1:-1] * (piece[-1, k] - piece[0, k])  # ends to the bit
        if path_time(straightened, speeds) >= (1.0 - STRAIGHTENED_GAIN) * path_time(piece, speeds):
            continue
        if edges.chain_free(straightened):
            path = path.copy()
            path[i : j + 1] = straightened
    return path


def _skip_vertices(path: FloatArray, edges: Edges) -> FloatArray:
    """``path`` from each kept vertex straight to the farthest later vertex it sees."""
    kept, i = [path[0]], 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and edges.free_fraction(path[i], path[j]) < 1.0:
            j -= 1
        kept.append(path[j])
        i = j
    return np.array(kept)


def _drop_collinear(path: FloatArray) -> FloatArray:
    """``path`` without vertices on the straight line between their neighbours."""
    keep = [0]
    for k in range(1, len(path) - 1):
        before, after = path[k] - path[keep[-1]], path[k + 1] - path[k]
        if _sine(before, after) > 1e-9:
            keep.append(k)
    keep.append(len(path) - 1)
    return path[keep]


def _sine(u: FloatArray, v: FloatArray) -> float:
    """``|sin|`` of the angle between ``u`` and ``v`` (0 if either is zero)."""
    nu, nv = float(np.linalg.norm(u)), float(np.linalg.norm(v))
    if nu == 0.0 or nv == 0.0:
        return 0.0
    c = float(u @ v) / (nu * nv)
    return math.sqrt(max(0.0, 1.0 - c * c))
