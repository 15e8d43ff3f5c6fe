"""Straight edges between configurations: their validity, checked in batches, and path shortening.

A sampling planner spends most of its time asking whether straight edges are valid. Here
an edge is checked as OMPL checks a motion, at configurations a fixed robot motion apart
(``resolution_m``, a motion bound ``sum_j R_j |dq_j|`` [m] with per-joint weights), but every
edge of a call in batched calls to the validity check, which is what makes it fast in
Python: a coarse pass over every edge, then the rest of each edge up to where the coarse pass
found it blocked (OMPL stops at a motion's first invalid state in the same spirit). The same
checks shorten a found path: random shortcuts (a straight edge between two points on it
replaces what lies between when it is valid), then skipping vertices (from each vertex
straight to the farthest one it sees), then dropping collinear vertices.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
Validity = Callable[[FloatArray], BoolArray]
"""``(N, d) -> (N,)``: whether each configuration is valid (clear of the margin)."""
COARSE_STRIDE = 8
"""Configurations an edge's coarse pass steps over (:meth:`Edges.free_fractions`)."""
WHOLE_BELOW = 48
"""Edges of fewer configurations are checked whole in the first pass: a second call of the
validity check would cost more than it saves (a 5-joint arm's edges have 16-100; a 6- or
7-joint arm's, whose joints move points farther, 60 and more; ``docs/tuning.md``)."""


class Edges:
    """Validity of straight edges, each checked in one batch; counts the configurations checked."""

    def __init__(self, valid: Validity, weights: FloatArray, resolution_m: float) -> None:
        self.valid, self.weights, self.resolution_m, self.checks = valid, weights, resolution_m, 0

    def free_fraction(self, a: FloatArray, b: FloatArray) -> float:
        """The fraction of the edge ``a -> b`` valid from ``a`` on, in [0, 1] (``a`` assumed valid)."""
        return self.free_fractions([(a, b)])[0]

    def free_fractions(self, edges: list[tuple[FloatArray, FloatArray]]) -> list[float]:
        """:meth:`free_fraction` of each edge, coarse to fine in at most two calls of the validity check.

        Every :data:`COARSE_STRIDE`-th configuration of every edge first (and its end; an edge
        of fewer than :data:`WHOLE_BELOW` configurations whole); then, of each edge, the others
        up to its first invalid one of those: an edge that hits an obstacle is not checked
        beyond it. The answer is that of checking every configuration.
        """
        counts = [
            max(1, math.ceil(float(np.abs(b - a) @ self.weights) / self.resolution_m)) for a, b in edges
        ]
        fractions = [np.arange(1, count + 1) / count for count in counts]
        points = [a + f[:, None] * (b - a) for (a, b), f in zip(edges, fractions, strict=True)]
        if max(counts) < WHOLE_BELOW:  # every edge whole, in one call (no masks: this is the hot path)
            answers = self.valid(np.concatenate(points))
            self.checks += len(answers)
            bounds = np.cumsum([0, *counts])
            ok = [answers[start:stop] for start, stop in itertools.pairwise(bounds)]
        else:
            ok = self._coarse_to_fine(points, counts)
        found = []
        for count, f, part in zip(counts, fractions, ok, strict=True):
            first_bad = count if part.all() else int(np.argmin(part))
            found.append(1.0 if first_bad == count else 0.0 if first_bad == 0 else float(f[first_bad - 1]))
        return found

    def _coarse_to_fine(self, points: list[FloatArray], counts: list[int]) -> list[BoolArray]:
        """Each edge's validity, checked up to its first invalid configuration (module docstring)."""
        coarse = []
        for count in counts:
            rows = np.ones(count, dtype=bool)
            if count >= WHOLE_BELOW:
                rows[:] = False
                rows[COARSE_STRIDE - 1 :: COARSE_STRIDE] = True
                rows[-1] = True
            coarse.append(rows)
        ok = [np.ones(count, dtype=bool) for count in counts]
        self._check(points, coarse, ok)
        fine = []
        for rows, part in zip(coarse, ok, strict=True):
            rest = ~rows
            if rest.any():
                blocked = np.flatnonzero(~part)
                if blocked.size:
                    rest[blocked[0] :] = False  # nothing past the first invalid coarse one matters
            fine.append(rest)
        if any(rest.any() for rest in fine):
            self._check(points, fine, ok)
        return ok

    def _check(self, points: list[FloatArray], rows: list[BoolArray], ok: list[BoolArray]) -> None:
        """Check ``points[k][rows[k]]`` of every edge ``k`` in one call; write the answers into ``ok``."""
        answers = self.valid(np.concatenate([p[r] for p, r in zip(points, rows, strict=True)]))
        self.checks += len(answers)
        offset = 0
        for part, r in zip(ok, rows, strict=True):
            size = int(np.count_nonzero(r))
            part[r] = answers[offset : offset + size]
            offset += size


def shortcut(path: FloatArray, edges: Edges, rng: np.random.Generator, attempts: int) -> FloatArray:
    """Shorten ``path`` by ``attempts`` random shortcuts between points on its edges."""
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
        if edges.free_fraction(a, b) == 1.0:
            path = np.concatenate([path[: i + 1], [a, b], path[j + 1 :]])
    return _drop_collinear(_skip_vertices(path, edges))


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
