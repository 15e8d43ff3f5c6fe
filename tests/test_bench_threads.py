"""``scripts/bench_threads.py``: planning time on one thread and two, idle and beside spinning processes."""

from __future__ import annotations

import multiprocessing
from pathlib import Path

import pytest

from .conftest import load_script, script_table

SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


def test_the_spinning_processes_run_while_the_block_runs_and_are_gone_after() -> None:
    script = load_script("bench_threads")
    before = set(multiprocessing.active_children())
    with script.busy(2):
        spinning = set(multiprocessing.active_children()) - before
        assert len(spinning) == 2 and all(process.is_alive() for process in spinning)
    assert not any(process.is_alive() for process in spinning)
    assert not spinning & set(multiprocessing.active_children())


@pytest.mark.slow
def test_each_scene_is_planned_on_one_thread_and_two_idle_and_loaded() -> None:
    rows = script_table("bench_threads", "--scenes", str(SHELF), "--busy", "1")
    assert [row[:3] for row in rows[1:]] == [["scenes", "no spinner", "1"], ["scenes", "1 spinning", "1"]]
    for row in rows[1:]:
        one, two = (float(cell.split()[0]) for cell in row[3:5])  # medians rounded to the ms
        assert one > 0 and two > 0 and float(row[5]) == pytest.approx(two / one, rel=0.05)
