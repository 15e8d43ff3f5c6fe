"""``scripts/bench_ik.py``: the IK on the example arms and the PR2, as a user runs it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_ik.py"


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    """The script in a new process with ``arguments``."""
    return subprocess.run(
        [sys.executable, str(SCRIPT), *arguments], capture_output=True, text=True, timeout=600, check=False
    )


@pytest.mark.slow
def test_the_benchmark_prints_a_row_per_arm() -> None:
    completed = run("--targets", "2", "--seed", "4", "--robots", "ur5", "pr2")
    assert completed.returncode == 0, completed.stderr[-2000:]
    rows = {line.split()[0]: line.split() for line in completed.stdout.splitlines()[1:]}
    assert set(rows) == {"ur5", "pr2"}
    for row in rows.values():  # solved of 2 targets, then the times and ratios
        assert 0 < int(row[1]) <= 2 and row[2] == "/" and row[3] == "2"
        move_s, over_drawn, worst = (float(value) for value in row[5:8])
        assert move_s > 0.0 and 0.0 < over_drawn <= worst


def test_a_bad_target_count_is_one_line_naming_it() -> None:
    completed = run("--targets", "0")
    assert completed.returncode == 2
    assert "argument --targets: 0 must be an integer >= 1" in completed.stderr
    assert "Traceback" not in completed.stderr
