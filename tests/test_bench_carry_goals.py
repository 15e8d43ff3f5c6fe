"""``scripts/bench_carry_goals.py``: upright carries to a pose, the goal chosen on the constraint, as run."""

from __future__ import annotations

import pytest

from .conftest import script_table


@pytest.mark.slow
def test_the_benchmark_plans_every_carry_and_compares_the_moved_goals_with_the_nearest() -> None:
    rows = script_table("bench_carry_goals", "--carries", "4", "--robots", "panda", "--against-nearest")
    assert [row[0] for row in rows[1:]] == ["panda"]
    planned, carries = (int(v) for v in rows[1][1].split("/"))
    moved = int(rows[1][4])
    assert planned == carries == 4 and 1 <= moved <= carries  # seed 3 moves a goal off the nearest
    to_pose, to_nearest = (int(v) for v in rows[1][5].split("/"))
    assert to_pose == moved and 0 <= to_nearest <= moved
