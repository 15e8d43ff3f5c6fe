"""The rule every certified check updates its samples by: exact where known, else a true lower bound;
and how a check is stopped between its pieces of work."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.collision.decisive import (
    COARSE_BELOW,
    COARSE_STRIDE,
    ask,
    below_coal,
    certified,
    chunked,
    coal_error_m,
    exact_below,
    first_rows,
    propagated_bounds,
    with_neighbours,
)

from .conftest import after_calls


@pytest.mark.parametrize("coarse_from", [1, COARSE_BELOW])
def test_the_first_rows_are_a_stride_of_many_in_doubt_and_all_of_few(coarse_from: int) -> None:
    rows = np.flatnonzero(np.random.default_rng(8).uniform(size=2000) < 0.3)
    assert first_rows(rows, coarse_from).tolist() == rows[::COARSE_STRIDE].tolist()
    few = rows[: coarse_from - 1]
    assert first_rows(few, coarse_from).tolist() == few.tolist()  # empty where a stride starts at 1
    assert first_rows(rows[:COARSE_BELOW]).tolist() == rows[:COARSE_BELOW:COARSE_STRIDE].tolist()
    assert first_rows(rows[: COARSE_BELOW - 1]).tolist() == rows[: COARSE_BELOW - 1].tolist()


def test_the_samples_stay_below_a_distance_that_moves_no_faster_than_the_slack() -> None:
    rng = np.random.default_rng(5)
    for _ in range(200):
        count = int(rng.integers(2, 60))
        slack = rng.uniform(0.0, 0.01, count - 1)  # how far the distance may move per interval [m]
        reach = np.concatenate([[0.0], np.cumsum(slack)])
        true = np.concatenate([[rng.uniform(-0.05, 0.2)], rng.uniform(-1, 1, count - 1) * slack]).cumsum()
        known = rng.random(count) < 0.3
        bounds = true - rng.uniform(0.0, 0.05, count)  # the cheap bounds: below the truth
        error = coal_error_m(true)
        exact = np.where(known, true + rng.uniform(0.0, 1.0, count) * error, bounds)  # coal's, a hair above
        values = with_neighbours(exact, known, bounds, reach)
        np.testing.assert_array_equal(values[known], exact[known])
        assert np.all(values[~known] <= true[~known] + 1e-12)  # never above the truth
        assert np.all(values >= bounds)  # never worse than the cheap bound
        # and exactly the better of the two where both exist (the rule's definition)
        best = np.maximum(bounds, below_coal(propagated_bounds(exact, known, reach)))
        np.testing.assert_array_equal(values[~known], best[~known])


def test_samples_counted_at_the_exact_ceiling_decide_the_check_as_their_values_do() -> None:
    # values at or above exact_below(margin, slack) may be replaced by that ceiling (a lower
    # bound): the certified minimum stays on the same side of the margin
    rng = np.random.default_rng(9)
    for _ in range(300):
        count = int(rng.integers(2, 40))
        slack = rng.uniform(0.0, 0.01, count - 1)
        margin = float(rng.uniform(0.0, 0.02))
        # a distance moves by at most the slack over each interval
        steps = rng.uniform(-1, 1, count - 1) * slack
        values = rng.uniform(margin - 0.01, margin + 0.05) + np.concatenate([[0.0], steps.cumsum()])
        ceiling = exact_below(margin, slack)
        assert ceiling == margin + slack.max()
        counted = np.minimum(values, ceiling)
        exact_ok = certified(values, slack).min() >= margin
        counted_ok = certified(counted, slack).min() >= margin
        assert exact_ok == counted_ok


def test_coal_error_is_a_micrometre_below_a_metre_and_relative_above() -> None:
    np.testing.assert_allclose(
        coal_error_m(np.array([0.0, -0.3, 0.999, 2.0, -5.0])), [1e-6, 1e-6, 1e-6, 2e-6, 5e-6]
    )
    np.testing.assert_allclose(below_coal(np.array([0.1, 3.0])), [0.1 - 1e-6, 3.0 - 3e-6])


def test_a_check_in_chunks_is_the_check_in_one_call_and_stops_between_chunks() -> None:
    q = np.random.default_rng(4).normal(size=(1000, 3))

    def rows(batch: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # each row its own: as coal's queries
        return np.linalg.norm(batch, axis=1), np.argmax(batch, axis=1)

    whole = rows(q)
    asked, never = after_calls(10**9)
    for got, expected in zip(chunked(rows, q, never, rows=64), whole, strict=True):
        np.testing.assert_array_equal(got, expected)
    assert len(asked) == 16  # before each of the 1000 / 64 pieces
    np.testing.assert_array_equal(chunked(lambda b: b.sum(axis=1), q, never, rows=64), q.sum(axis=1))
    asked, third = after_calls(2)
    with pytest.raises(ck.CheckStoppedError, match="stopped by its caller before its verdict"):
        chunked(rows, q, third, rows=64)
    assert len(asked) == 3  # two pieces computed, stopped before the third
    ask(None)  # no stop: nothing asked
    with pytest.raises(ck.CheckStoppedError):
        ask(lambda: True)


def test_coal_error_of_a_float_is_the_arrays_to_the_bit() -> None:
    rng = np.random.default_rng(3)
    for distance in [0.0, -0.0, 1.0, -1.0, *rng.uniform(-5.0, 5.0, 200).tolist()]:
        error = coal_error_m(distance)
        assert isinstance(error, float)
        assert error == float(coal_error_m(np.array([distance]))[0])
