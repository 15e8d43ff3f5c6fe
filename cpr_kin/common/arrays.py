"""Array helpers NumPy has, without what they cost a new process."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray


def distinct_sorted(first: ArrayLike, *others: ArrayLike) -> NDArray[Any]:
    """The distinct values of the arrays given, sorted: ``np.union1d`` of two, ``np.unique`` of one.

    For values without NaN (each NaN stays, where ``np.unique`` keeps one). NumPy 2's
    ``np.unique`` imports ``numpy.ma`` at its first call: 9 ms of a new ``cpr-plan`` process,
    which has no other use for it.
    """
    ordered = np.sort(np.concatenate([np.ravel(values) for values in (first, *others)]))
    new = np.ones(ordered.size, dtype=bool)
    np.not_equal(ordered[1:], ordered[:-1], out=new[1:])
    return ordered[new]


def finite_median(values: ArrayLike, axis: int = 0) -> NDArray[np.float64]:
    """``np.median(values, axis)`` of finite values, without the ``numpy.ma`` its NaN check imports.

    The middle value along ``axis``, or the mean of the two middle values where the count is
    even: NumPy's own arithmetic, so the same to the bit. An empty axis is an error.
    """
    ordered = np.sort(np.asarray(values, dtype=float), axis=axis)
    count = ordered.shape[axis]
    if count == 0:
        raise ValueError("the median of no values")
    upper = np.take(ordered, count // 2, axis=axis)
    if count % 2:
        return np.asarray(upper)
    return np.asarray(np.mean(np.stack([np.take(ordered, count // 2 - 1, axis=axis), upper]), axis=0))
