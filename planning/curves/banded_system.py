"""The septic smoothing spline's normal equations: banded assembly and exact elimination.

Ordered node by node (value and its first three derivatives per node), segment ``i`` touches
unknowns ``4i .. 4i + 7``, so the normal equations of :mod:`planning.curves.spline` are
symmetric and banded (half-bandwidth 7). Values that are not free (pinned nodes, rest-end
derivatives) become identity rows and columns, their couplings moving to the right-hand side:
an exact elimination that keeps the band and the positive definiteness, solved by LAPACK's
banded Cholesky (``dpbtrf``, ``dpbtrs``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planning.curves.banded_cholesky import band_cholesky
from planning.curves.hermite import CONTINUITY, ENERGY, node_scaling
from planning.errors import SplineError

FloatArray = NDArray[np.float64]

PER_NODE = CONTINUITY + 1
"""Unknowns per node: the value and its first three derivatives."""
_BAND = 2 * PER_NODE - 1  # half-bandwidth of the normal equations

_D, _C = np.meshgrid(np.arange(_BAND + 1), np.arange(2 * PER_NODE), indexing="ij")
_BAND_MASK = (_C + _D < 2 * PER_NODE).astype(float)
_BAND_ROWS = np.minimum(_C + _D, 2 * PER_NODE - 1)
_BAND_COLS = _C
_OFFSETS = np.arange(-_BAND, _BAND + 1)
_ABS_OFFSETS = np.abs(_OFFSETS)
_DIAGONALS = np.arange(1, _BAND + 1)


def assemble_band(h: FloatArray, a: tuple[float, float, float], n_nodes: int) -> FloatArray:
    """Lower banded storage ``(8, 4 (N + 1))`` of the integral term of the normal equations.

    Segment ``i`` adds ``D_h E D_h`` (E: the weighted derivative energies in normalised
    time, D_h: node-derivative scaling) on unknowns ``4i .. 4i + 7``, i.e. on nodes ``i``
    and ``i + 1``; the blocks are added node by node, without a scatter.
    """
    energy = sum(
        coef * h[:, None, None] ** (1 - 2 * r) * ENERGY[r]
        for r, coef in zip((1, 2, 3), a, strict=True)
        if coef
    )
    scale = node_scaling(h)
    blocks = np.asarray(energy) * scale[:, :, None] * scale[:, None, :]
    segment_band = blocks[:, _BAND_ROWS, _BAND_COLS] * _BAND_MASK  # [i, d, c] = B_i[c + d, c]
    band = np.zeros((_BAND + 1, n_nodes, PER_NODE))
    halves = segment_band.reshape(len(h), _BAND + 1, 2, PER_NODE)
    band[:, :-1] += halves[:, :, 0].transpose(1, 0, 2)
    band[:, 1:] += halves[:, :, 1].transpose(1, 0, 2)
    return band.reshape(_BAND + 1, -1)


@dataclass(frozen=True)
class Structure:
    """Index arrays that depend only on the node count and which values are fixed."""

    weighted: NDArray[np.intp]  # nodes with a finite weight p_i
    pinned: NDArray[np.intp]  # nodes met exactly
    fixed: NDArray[np.intp]  # fixed unknowns (pinned values, rest-end derivatives)
    zero_diagonal: NDArray[np.intp]  # band entries (diagonal, column) in the fixed unknowns' rows
    zero_column: NDArray[np.intp]
    coupling_rows: NDArray[np.intp]  # free rows of the pinned unknowns' columns ...
    coupling_nodes: NDArray[np.intp]  # ... the pinned node each belongs to ...
    coupling_diagonal: NDArray[np.intp]  # ... and where the matrix entry sits in the band
    coupling_column: NDArray[np.intp]


@lru_cache(maxsize=64)
def structure(n_nodes: int, exact_key: bytes, rest: bool) -> Structure:
    """The index arrays of the elimination for ``n_nodes`` nodes (cached).

    ``exact_key`` is the bytes of the boolean mask of nodes met exactly; ``rest`` fixes the
    end velocities and accelerations.
    """
    exact = np.frombuffer(exact_key, dtype=bool)
    n = PER_NODE * n_nodes
    fixed = np.zeros(n, dtype=bool)
    fixed[PER_NODE * np.flatnonzero(exact)] = True
    if rest:
        for node in (0, n_nodes - 1):
            fixed[PER_NODE * node + 1 : PER_NODE * node + 3] = True  # y' = y'' = 0
    fixed_index = np.flatnonzero(fixed)
    row_cols = fixed_index[None, :] - _DIAGONALS[:, None]  # fixed rows, left of the diagonal
    inside = row_cols >= 0
    pinned = np.flatnonzero(exact)
    k = PER_NODE * pinned[:, None]
    rows = k + _OFFSETS  # (m, 15): the band of each pinned unknown's column
    band_cols = np.where(_OFFSETS >= 0, k, k + _OFFSETS)
    valid = (rows >= 0) & (rows < n) & (band_cols >= 0) & (_OFFSETS != 0)
    valid[valid] = ~fixed[rows[valid]]
    which, offset = np.nonzero(valid)
    return Structure(
        weighted=np.flatnonzero(~exact),
        pinned=pinned,
        fixed=fixed_index,
        zero_diagonal=np.broadcast_to(_DIAGONALS[:, None], row_cols.shape)[inside],
        zero_column=row_cols[inside],
        coupling_rows=rows[which, offset],
        coupling_nodes=pinned[which],
        coupling_diagonal=_ABS_OFFSETS[offset],
        coupling_column=band_cols[which, offset],
    )


def coupling_matrix(band: FloatArray, structure: Structure, p: FloatArray) -> Any:
    """``W`` with right-hand side ``W @ f`` for node values ``f``.

    Weighted node ``i`` contributes ``p_i f_i`` to its value row. A pinned node's value
    is its own (identity) row, and its column of the matrix, times ``f_i``, moves to the
    right-hand side of the free rows. Every (row, node) pair occurs once.
    """
    n, n_nodes = band.shape[1], len(p)
    weighted, pinned = structure.weighted, structure.pinned
    r = np.concatenate([PER_NODE * weighted, PER_NODE * pinned, structure.coupling_rows])
    c = np.concatenate([weighted, pinned, structure.coupling_nodes])
    v = np.concatenate(
        [p[weighted], np.ones(pinned.size), -band[structure.coupling_diagonal, structure.coupling_column]]
    )
    if n * n_nodes <= 200_000:
        dense = np.zeros((n, n_nodes))
        dense[r, c] = v
        return dense
    from scipy import sparse  # only for long splines: a plan's few segments need no SciPy

    return sparse.csr_array((v, (r, c)), shape=(n, n_nodes))


def factorised_system(
    steps: FloatArray, a: tuple[float, float, float], p: FloatArray, exact: NDArray[np.bool_], ends: str
) -> tuple[FloatArray, Any]:
    """The Cholesky factor of the normal equations and the coupling matrix ``W``.

    Args:
        steps: ``(N,)`` segment durations [s].
        a: the velocity, acceleration and jerk weights.
        p: ``(N + 1,)`` node weights (``inf`` where ``exact``).
        exact: ``(N + 1,)`` nodes met exactly.
        ends: ``"rest"`` fixes velocity and acceleration at both ends to zero.

    Returns:
        The factor in LAPACK's lower band storage (:func:`band_cholesky_solve`'s input), and ``W`` such that
        the right-hand side for node values ``f`` is ``W @ f`` (:func:`coupling_matrix`).

    Raises:
        SplineError: the system is singular (too few nodes for the weights).
    """
    n_nodes = len(p)
    band = assemble_band(steps, a, n_nodes)
    elimination = structure(n_nodes, exact.tobytes(), ends == "rest")
    weighted = elimination.weighted
    band[0, PER_NODE * weighted] += p[weighted]
    coupling = coupling_matrix(band, elimination, p)
    # fixed unknowns become identity rows and columns: an exact elimination that keeps
    # the band and the positive definiteness
    band[:, elimination.fixed] = 0.0
    band[elimination.zero_diagonal, elimination.zero_column] = 0.0
    band[0, elimination.fixed] = 1.0
    factor, info = band_cholesky(np.ascontiguousarray(band))
    if info != 0:
        raise SplineError(
            f"the spline system is singular for a = {list(a)}, ends = '{ends}' and "
            f"{n_nodes} nodes; add nodes or a lower-order weight"
        )
    return factor, coupling
