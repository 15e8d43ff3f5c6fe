"""The array helpers against NumPy's own functions."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from cpr_kin.common.arrays import distinct_sorted, finite_median


@pytest.mark.parametrize("dtype", [np.int64, np.float64])
def test_distinct_sorted_is_numpys_union_and_unique(dtype: type) -> None:
    rng = np.random.default_rng(7)
    for size in (0, 1, 2, 5, 50):
        a: np.ndarray = rng.integers(0, 10, size).astype(dtype)
        b: np.ndarray = rng.integers(5, 15, 3).astype(dtype)
        for ours, numpys in [(distinct_sorted(a), np.unique(a)), (distinct_sorted(a, b), np.union1d(a, b))]:
            assert ours.dtype == numpys.dtype
            np.testing.assert_array_equal(ours, numpys)


def test_distinct_sorted_takes_lists_scalars_and_several_arrays() -> None:
    np.testing.assert_array_equal(distinct_sorted([3, 1, 3], [2], 1, np.array([[4, 1]])), [1, 2, 3, 4])
    assert distinct_sorted(np.array([-0.0, 0.0])).tolist() == [0.0]  # equal values: one kept


@pytest.mark.parametrize(
    ("call", "imported"),
    [
        ("distinct_sorted([2, 1, 2])", False),
        ("np.unique([2, 1, 2])", True),
        ("finite_median([[3.0, 1.0], [2.0, 5.0]])", False),
        ("np.median([[3.0, 1.0], [2.0, 5.0]], axis=0)", True),
    ],
)
def test_the_helpers_import_no_numpy_ma_where_numpys_own_do(call: str, imported: bool) -> None:
    # why the helpers are: if NumPy's unique or median stops importing numpy.ma, it will do again
    code = (
        "import sys, numpy as np; from cpr_kin.common.arrays import distinct_sorted, finite_median; "
        f"{call}; print('numpy.ma' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == [str(imported)]


def test_finite_median_is_numpys_median_to_the_bit() -> None:
    rng = np.random.default_rng(11)
    for shape in [(256, 3), (255, 4), (1, 2), (2, 5), (7,)]:
        values = rng.normal(size=shape) * 1e-2
        np.testing.assert_array_equal(finite_median(values), np.median(values, axis=0))
        if values.ndim == 2:
            np.testing.assert_array_equal(finite_median(values, axis=1), np.median(values, axis=1))
    with pytest.raises(ValueError, match="no values"):
        finite_median(np.zeros((0, 3)))
