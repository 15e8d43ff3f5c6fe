"""``scripts/bench_carry.py``: our upright carry beside roboplan's constrained RRT-Connect, as run."""

from __future__ import annotations

import pytest

from .conftest import script_table


@pytest.mark.slow
def test_the_benchmark_prints_a_row_with_both_planners_and_ours_keeps_the_constraint() -> None:
    rows = script_table("bench_carry", "--problems", "1", "--robots", "ur5")
    assert [row[0] for row in rows[1:]] == ["ur5"]
    ours, peer = (int(v) for v in rows[1][2].split("/"))
    assert ours == 1 and 0 <= peer <= 1
    tilt = float(rows[1][5].split("/")[0])
    clearance = float(rows[1][6].split("/")[0])
    assert tilt <= 5.0 and clearance >= 20.0  # ours: within the constraint and the margin, every ms
