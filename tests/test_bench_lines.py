"""``scripts/bench_lines.py``: our tool lines beside roboplan's Cartesian planner, as a user runs it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from .conftest import script_table

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_lines.py"


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    """The script in a new process with ``arguments``."""
    return subprocess.run(
        [sys.executable, str(SCRIPT), *arguments], capture_output=True, text=True, timeout=600, check=False
    )


@pytest.mark.slow
def test_the_benchmark_prints_a_row_per_robot_with_both_planners() -> None:
    rows = script_table("bench_lines", "--lines", "3", "--seed", "2", "--robots", "cpr", "panda")
    assert [row[0] for row in rows[1:]] == ["cpr", "panda"]
    for row in rows[1:]:
        ours, peer = (int(v) for v in row[2].split("/"))
        assert 0 <= ours <= 3 and 0 <= peer <= 3
        largest = row[5].split("/")[0].strip()
        assert largest == "nan" or float(largest) <= 1.0  # ours: sampled deviation [mm] within 1 mm


def test_a_bad_line_count_is_one_line_naming_it() -> None:
    completed = run("--lines", "0")
    assert completed.returncode == 2
    assert "argument --lines: 0 must be an integer >= 1" in completed.stderr
    assert "Traceback" not in completed.stderr


@pytest.mark.slow
def test_a_robot_roboplan_cannot_load_leaves_ours_and_says_why() -> None:
    """roboplan 0.7.0 refuses the Z1 of example-robot-data (a link and a joint share a frame name)."""
    pytest.importorskip("roboplan.core", reason="the bench extra's roboplan")
    completed = run("--lines", "2", "--seed", "87", "--robots", "z1")
    assert completed.returncode == 0, completed.stderr[-2000:]
    row = next(line.split("|")[1:-1] for line in completed.stdout.splitlines() if line.startswith("| z1 "))
    ours, peer = (part.strip() for part in row[2].split("/"))
    assert int(ours) >= 1 and peer == "0"
    assert "roboplan could not load z1: RuntimeError: " in completed.stdout


def test_a_robot_it_does_not_know_is_one_line_naming_the_choices() -> None:
    completed = run("--robots", "kuka")
    assert completed.returncode == 2
    assert "argument --robots: invalid choice: 'kuka' (choose from 'cpr', 'panda'" in completed.stderr
    assert "Traceback" not in completed.stderr
