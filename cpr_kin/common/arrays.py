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
