"""``scripts/bench_ik.py``: the IK with and without its patience on the example arms, as a user runs it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cpr_kin.model.packages import EXAMPLE_ROBOTS

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_ik.py"


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    """The script in a new process with ``arguments``."""
    return subprocess.run(
        [sys.executable, str(SCRIPT), *arguments], capture_output=True, text=True, timeout=600, check=False
    )


@pytest.mark.slow
def test_the_benchmark_prints_a_row_per_arm() -> None:
    completed = run("--targets", "2", "--seed", "4")
    assert completed.returncode == 0, completed.stderr[-2000:]
    rows = {line.split()[0]: line.split() for line in completed.stdout.splitlines()[1:]}
    assert set(rows) == set(EXAMPLE_ROBOTS)
    for row in rows.values():  # solved new / old of 2 targets each
        assert 0 <= int(row[1]) <= 2 and row[2] == "/" and 0 <= int(row[3]) <= 2


def test_a_bad_target_count_is_one_line_naming_it() -> None:
    completed = run("--targets", "0")
    assert completed.returncode == 2
    assert "argument --targets: 0 must be an integer >= 1" in completed.stderr
    assert "Traceback" not in completed.stderr
