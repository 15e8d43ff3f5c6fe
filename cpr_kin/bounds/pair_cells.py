"""A grid over the one or two joints between a pair's geometries, its cells within a slack.

A pair's distance changes by at most ``sum_j r_j |dq_j|`` (:func:`cpr_kin.bounds.reach.relative_radii`),
and only by the joints between its geometries. A grid over those joints (a revolute joint's
angle taken modulo a turn where its range is a turn or more; any other joint's range tiled
within its limits) whose cells are ``h_j`` wide with ``sum_j r_j h_j / 2`` at most a *slack*
holds the pair's distance, anywhere in a cell, within that slack of its distance at the cell's
centre. What a cell is known to clear, and where it is not, the distance at its centre, are
kept by :class:`cpr_kin.collision.near_cells.NearCells`; :func:`cell_states` reads them for a
batch of configurations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.reach import joint_axis
from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]
Float32Array = NDArray[np.float32]
IntArray = NDArray[np.int64]

MAX_JOINTS = 2
"""A pair with more joints between its geometries has no grid."""
MAX_CELLS = 1 << 16
"""A pair whose grid would hold more cells has none: a plan would rarely meet a cell twice."""

CLEAR, DOUBTFUL, UNKNOWN = 0, 1, 2
"""A configuration's state: every pair's cell clears its margin; some pair's does not, or the
configuration lies beyond a grid (coal decides); some pair's cell is not yet tested at it."""


@njit
def cell_states(
    batch: FloatArray,
    joints: IntArray,
    origin: FloatArray,
    step: FloatArray,
    turn: FloatArray,
    counts: IntArray,
    strides: IntArray,
    offsets: IntArray,
    radius: FloatArray,
    cleared: Float32Array,
    refused: Float32Array,
    centre_m: Float32Array,
    levels: Float32Array,
    cells: IntArray,
    states: NDArray[np.int8],
) -> None:
    """Write each configuration's state into ``states`` ``(N,)`` and its cells into ``cells`` ``(N, K)``.

    The arguments after ``batch`` are :class:`CellGrids`' arrays, then what each cell is known
    to clear (``cleared``, the largest margin [m]) and not (``refused``, the smallest), a lower
    bound of the pair's distance at the cell's centre (``centre_m`` [m], ``-inf`` where not
    measured), and the margin [m] each pair must clear (``levels``). Where a cell does not clear
    the margin, a configuration in it still does where the centre's bound less
    ``sum_j r_j |q_j - c_j|`` (its offset from the centre) exceeds it. A row's cells are all
    written where it is UNKNOWN; elsewhere those after the first DOUBTFUL pair are not.
    """
    for n in range(batch.shape[0]):
        state = np.int64(CLEAR)  # typed int64, not the constants' literal types (which pycc cannot unify)
        for k in range(joints.shape[0]):
            flat = offsets[k]
            moved = 0.0  # how far the pair's distance may be from the centre's [m]
            for j in range(joints.shape[1]):
                joint = joints[k, j]
                if joint < 0:
                    break
                x = batch[n, joint] - origin[k, j]
                if turn[k, j] > 0.0:
                    x = x % turn[k, j]
                elif x < 0.0 or x > step[k, j] * counts[k, j]:
                    flat = -1
                    break
                index = min(int(x / step[k, j]), counts[k, j] - 1)
                flat += index * strides[k, j]
                moved += radius[k, j] * abs(x - (index + 0.5) * step[k, j])
            cells[n, k] = flat
            if flat < 0:
                state = np.int64(DOUBTFUL)
                break
            if refused[flat] <= levels[k]:
                if centre_m[flat] - moved > levels[k]:
                    continue  # this configuration, near the centre, clears it
                state = np.int64(DOUBTFUL)
                break
            if cleared[flat] < levels[k]:
                state = np.int64(UNKNOWN)
        states[n] = state


@dataclass(frozen=True)
class CellGrids:
    """The near pairs' grids, pair ``k`` in row ``k`` of each ``(K, MAX_JOINTS)`` array.

    Attributes:
        slack_m: ``(K,)`` how far a pair's distance may be from its distance at the cell's centre [m].
        joints: the ``q`` index of each joint of the grid, ``-1`` past the last.
        origin: where the first cell begins [rad, m].
        step: the cells' width [rad, m].
        turn: a wrapped joint's period (2 pi) [rad]; 0 for a joint tiled within its limits.
        counts: the cells along the joint.
        strides: how far apart in the flat index two cells neighbouring along the joint are.
        offsets: ``(K,)`` where the pair's cells begin in the flat index.
        radius: how fast the pair's distance may change with the joint [m/rad, m/m]
            (:func:`cpr_kin.bounds.reach.relative_radii`), 0 past the last.
        size: the cells of every grid.
    """

    slack_m: FloatArray
    joints: IntArray
    origin: FloatArray
    step: FloatArray
    turn: FloatArray
    counts: IntArray
    strides: IntArray
    offsets: IntArray
    radius: FloatArray
    size: int

    def arrays(
        self,
    ) -> tuple[IntArray, FloatArray, FloatArray, FloatArray, IntArray, IntArray, IntArray, FloatArray]:
        """The arrays :func:`cell_states` takes after the configurations."""
        grid = (self.joints, self.origin, self.step, self.turn, self.counts, self.strides, self.offsets)
        return (*grid, self.radius)

    def centres(self, k: int, cells: IntArray, rows: FloatArray) -> FloatArray:
        """``rows`` ``(M, nq)`` with pair ``k``'s joints moved to the centres of its ``cells`` ``(M,)``."""
        centred = rows.copy()
        local = cells - self.offsets[k]
        for j in np.flatnonzero(self.joints[k] >= 0).tolist():
            index = (local // self.strides[k, j]) % self.counts[k, j]
            centred[:, self.joints[k, j]] = self.origin[k, j] + (index + 0.5) * self.step[k, j]
        return centred


@dataclass(frozen=True)
class _Axis:
    """One joint of a pair's grid: its ``q`` index, cells, where they begin, their width and its period."""

    joint: int
    count: int
    origin: float
    step: float
    turn: float
    radius: float


def _axes(model: Any, radii: FloatArray, slack_m: float) -> list[_Axis] | None:
    """The joints of a grid of one pair whose distance changes by ``radii`` ``(nj,)``, ``None`` without one.

    The rule of :func:`cell_grids`, for one pair.
    """
    moved = np.flatnonzero(radii > 0.0).tolist()
    if not 0 < len(moved) <= MAX_JOINTS:
        return None
    axes = []
    for joint in moved:
        prismatic, _ = joint_axis(model.joints[joint + 1])
        lower, upper = float(model.lowerPositionLimit[joint]), float(model.upperPositionLimit[joint])
        wraps = not prismatic and not upper - lower < 2.0 * math.pi  # NaN limits wrap too
        span = 2.0 * math.pi if wraps else upper - lower
        if not (math.isfinite(span) and span > 0.0):
            return None
        count = math.ceil(span * len(moved) * radii[joint] / (2.0 * slack_m))
        origin, turn = (0.0, 2.0 * math.pi) if wraps else (lower, 0.0)
        axes.append(_Axis(joint, count, origin, span / count, turn, float(radii[joint])))
    if math.prod(axis.count for axis in axes) > MAX_CELLS:
        return None
    return axes


def has_grid(model: Any, radii: FloatArray, slack_m: float) -> bool:
    """Whether a pair whose distance changes by ``radii`` ``(nj,)`` per joint speed can have a grid.

    At most :data:`MAX_JOINTS` joints between its geometries, each within finite limits (or a
    revolute joint's turn), and at most :data:`MAX_CELLS` cells of ``slack_m`` [m].
    """
    return _axes(model, radii, slack_m) is not None


def cell_grids(model: Any, pair_radii: FloatArray, slack_m: FloatArray) -> CellGrids | None:
    """The grids of pairs whose distances change by ``pair_radii`` ``(K, nj)`` per joint speed.

    ``None`` where some pair has no grid (:func:`has_grid`): no joint or more than
    :data:`MAX_JOINTS` between its geometries, a prismatic joint without finite limits, or more
    than :data:`MAX_CELLS` cells. A revolute joint whose range is a turn or more wraps (its angle
    modulo a turn: the geometry is the same); another is tiled within its limits, and a
    configuration beyond them has no cell. A joint ``j`` of ``J`` gets cells of width ``h_j``
    with ``r_j h_j / 2 <= slack / J``.
    """
    shape = (len(pair_radii), MAX_JOINTS)
    joints, counts = np.full(shape, -1, dtype=np.int64), np.ones(shape, dtype=np.int64)
    origin, step, turn, radius = np.zeros(shape), np.ones(shape), np.zeros(shape), np.zeros(shape)
    offsets, size = np.zeros(shape[0], dtype=np.int64), 0
    for k, (radii, slack) in enumerate(zip(pair_radii, slack_m.tolist(), strict=True)):
        axes = _axes(model, radii, slack)
        if axes is None:
            return None
        for j, axis in enumerate(axes):
            joints[k, j], counts[k, j], origin[k, j] = axis.joint, axis.count, axis.origin
            step[k, j], turn[k, j], radius[k, j] = axis.step, axis.turn, axis.radius
        offsets[k], size = size, size + math.prod(counts[k].tolist())
    strides = np.cumprod(counts[:, ::-1], axis=1)[:, ::-1]  # row-major: the last joint's stride is 1
    strides = np.concatenate([strides[:, 1:], np.ones((shape[0], 1), dtype=np.int64)], axis=1)
    return CellGrids(slack_m, joints, origin, step, turn, counts, strides, offsets, radius, size)
