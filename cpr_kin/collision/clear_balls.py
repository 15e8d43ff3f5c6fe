"""Configurations where a pair's exact meshes were measured apart, each clearing those near it.

Between two configurations a pair's distance changes by at most ``sum_j r_j |q_j - c_j|``
(its relative radii, :func:`cpr_kin.bounds.reach.relative_radii`). So where coal measured the
pair's meshes ``d`` apart at ``c``, every ``q`` with ``sum_j r_j |q_j - c_j| < d - m`` keeps the
margin ``m``, and needs no coal. A concave link's hull may stay within a margin its mesh clears
over a region a search keeps coming back to (a UR10's wrist folded beside its forearm, near a
start or goal every candidate path shares), where each test of the meshes is a coal query on
triangles: the configurations measured there answer most of the later tests (docs/tuning.md,
Exact meshes).

The memory is a plan's own (each collision world makes its own), so a plan's answers never
depend on the plans before it; and it answers "clear" only where the bound proves it, so a
test's verdict is the meshes' either way.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.collision.decisive import coal_error_m

FloatArray = NDArray[np.float64]

KEPT = 1024
"""Measured configurations a pair keeps, the latest (a search moves on; a longer scan costs more)."""


class ClearBalls:
    """Per pair, the latest configurations its meshes were measured apart at, and how far apart.

    The memory of a margin test on the meshes (:class:`~cpr_kin.shapes.exact_pairs.MeasuredApart`).

    Args:
        pair_radii: ``(P, nq)`` how fast each pair's distance may change per joint speed
            [m/rad, m/m], joints in the configuration's order.
        kept: measured configurations kept per pair.

    Attributes:
        answered: tests answered from the memory, without coal.
    """

    def __init__(self, pair_radii: FloatArray, kept: int = KEPT) -> None:
        radii_of = np.asarray(pair_radii, dtype=float)
        self._joints = [np.flatnonzero(radii > 0.0) for radii in radii_of]
        self._moving = [radii[joints] for radii, joints in zip(radii_of, self._joints, strict=True)]
        self._kept = kept
        self._last: dict[int, int] = {}  # the slot that answered last: asked first
        self._centres: dict[int, FloatArray] = {}
        self._apart_m: dict[int, FloatArray] = {}
        self._added: dict[int, int] = {}
        self.answered = 0

    def clear(self, pair: int, q: FloatArray, margin_m: float) -> bool:
        """Whether pair ``pair`` surely keeps ``margin_m`` [m] at configuration ``q``, by what it measured."""
        added = self._added.get(pair, 0)
        if not added:
            return False
        centres, apart_m, radii = self._centres[pair], self._apart_m[pair], self._moving[pair]
        at = q[self._joints[pair]]
        last = self._last.get(pair, -1)
        if last >= 0 and float(np.abs(centres[last] - at) @ radii) < apart_m[last] - margin_m:
            self.answered += 1
            return True
        count = min(added, self._kept)
        room = apart_m[:count] - np.abs(centres[:count] - at) @ radii
        best = int(np.argmax(room))
        if room[best] > margin_m:
            self._last[pair] = best
            self.answered += 1
            return True
        return False

    def add(self, pair: int, q: FloatArray, distance_m: float) -> None:
        """Keep that pair ``pair``'s meshes are ``distance_m`` [m] apart (coal's distance) at ``q``.

        Kept less coal's error at that distance, the oldest of :data:`KEPT` dropped.
        """
        joints, added = self._joints[pair], self._added.get(pair, 0)
        if not added:
            self._centres[pair] = np.empty((self._kept, len(joints)))
            self._apart_m[pair] = np.empty(self._kept)
        slot = added % self._kept
        self._centres[pair][slot] = q[joints]
        self._apart_m[pair][slot] = distance_m - coal_error_m(float(distance_m))
        self._added[pair] = added + 1
