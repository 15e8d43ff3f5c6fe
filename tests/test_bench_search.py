"""``scripts/bench_search.py``: ours beside OMPL's pipeline on generated scenes, as a user runs it."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_search.py"


def run(*arguments: str) -> subprocess.CompletedProcess[str]:
    """The script in a new process with ``arguments``."""
    command = [sys.executable, str(SCRIPT), "--cli-runs", "0", *arguments]
    return subprocess.run(command, capture_output=True, text=True, timeout=600, check=False)


@pytest.mark.slow
def test_the_benchmark_prints_each_class_and_the_bound_with_a_refine_stall() -> None:
    pytest.importorskip("ompl")
    scenes = ("--scenes", "2", "--narrow", "1", "--kinds", "pillars", "--seed", "3")
    completed = run(*scenes, "--refine-stall", "8")
    assert completed.returncode == 0, completed.stderr[-2000:]
    out = completed.stdout
    assert "  regular " in out and "  pillars " in out
    assert "Ruckig's free-space bound" in out and "over 2 scenes" in out


@pytest.mark.slow
def test_the_bundled_scenes_count_each_as_its_own_class() -> None:
    pytest.importorskip("ompl")
    completed = run("--scenes", "1", "--narrow", "0", "--seed", "3", "--bundled", "--planner-seed", "2")
    assert completed.returncode == 0, completed.stderr[-2000:]
    out = completed.stdout
    assert "  shelf " in out and "  paper " in out and "paper_free" in out
    assert "over 3 scenes" in out


@pytest.mark.slow
def test_several_generator_seeds_end_with_issue_33_b_per_seed_and_the_median_of_medians() -> None:
    pytest.importorskip("ompl")
    completed = run("--scenes", "1", "--narrow", "1", "--kinds", "pillars", "--seed", "3", "4", "--bundled")
    assert completed.returncode == 0, completed.stderr[-2000:]
    out = completed.stdout
    assert "== generator seed 3" in out and "== generator seed 4" in out
    assert out.count("our duration / Ruckig's free-space bound") == 2
    summary = out[out.index("issue 33 B per generator seed") :]
    assert "seed 3 " in summary and "seed 4 " in summary
    assert "B.2 pillars" in summary  # the generated class, not the bundled paper scene's own search
    assert "of 2 seeds; the median of the seeds' medians" in summary


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (("--refine-stall", "-1"), "refine_stall = -1 must be an integer in [0, 10000]"),
        (("--planner-seed", "-1"), "seed = -1"),
        (("--scenes", "2", "--narrow", "3"), "narrow = 3 scenes; allowed: 0 to count = 2"),
        (("--seed", "3", "-1"), "argument --seed: -1 must be an integer >= 0"),
        (("--budget", "0"), "argument --budget: 0 must be a number > 0 s"),
    ],
)
def test_a_bad_argument_is_one_line_naming_it(arguments: tuple[str, ...], message: str) -> None:
    completed = run(*arguments)
    assert completed.returncode == 2
    assert message in completed.stderr and "Traceback" not in completed.stderr
