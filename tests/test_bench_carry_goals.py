"""``scripts/bench_carry_goals.py``: upright carries to a pose, the goal chosen on the constraint, as run."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_carry_goals.py"


@pytest.mark.slow
def test_the_benchmark_plans_every_carry_and_compares_the_moved_goals_with_the_nearest() -> None:
    completed = subprocess.run(
        [sys.executable, str(SCRIPT), "--carries", "4", "--robots", "panda", "--against-nearest"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr[-2000:]
    rows = [line.split("|")[1:-1] for line in completed.stdout.splitlines() if line.startswith("| ")]
    assert [row[0].strip() for row in rows[1:]] == ["panda"]
    planned, carries = (int(v) for v in rows[1][1].split("/"))
    moved = int(rows[1][4])
    assert planned == carries == 4 and 1 <= moved <= carries  # seed 3 moves a goal off the nearest
    to_pose, to_nearest = (int(v) for v in rows[1][5].split("/"))
    assert to_pose == moved and 0 <= to_nearest <= moved
