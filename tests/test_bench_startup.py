"""``scripts/bench_startup.py``: ``cpr-plan plan`` in new processes, beside the start-up floor."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from planning.io.bundled import paper_scene_path

from .conftest import load_script, run_script, script_table

SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


@pytest.mark.slow
def test_the_command_and_the_floor_are_timed_in_new_processes_each_against_the_floor() -> None:
    rows = script_table("bench_startup", "--scene", str(SHELF), "--runs", "2")
    assert rows[0] == ["command", "kernels", "wall s", "CPU s", "peak MiB", "wall / floor", "CPU / floor"]
    named = {row[0]: row[1:] for row in rows[1:]}
    assert set(named) == {"this checkout", "start-up floor"}
    kinds = ("ahead of time", "ahead of time, but numba loaded: a kernel it lacks", "numba")
    assert named["this checkout"][0] in kinds and named["start-up floor"][0] == "-"
    assert named["start-up floor"][4:] == ["1.00", "1.00"]  # the floor over itself
    mine, floor = (named[name] for name in ("this checkout", "start-up floor"))
    assert all(float(cell) > 0 for cell in mine[1:] + floor[1:])
    assert float(mine[1]) > float(floor[1]) and float(mine[3]) > float(floor[3])  # it imports the floor


def test_a_scene_that_is_not_there_is_one_line_and_exit_1() -> None:
    done = run_script("bench_startup", "--scene", "no_such.yaml", timeout_s=60)
    assert done.returncode == 1
    assert done.stderr.strip() == "--scene no_such.yaml: no such file; give a scene file (YAML)"


@pytest.mark.slow
@pytest.mark.parametrize(("mode", "imported"), [("jit", "True"), ("ahead", None)])
def test_the_untimed_run_says_whether_the_plan_imported_numba(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, mode: str, imported: str | None
) -> None:
    """What tells a module compiled ahead of time that lacked a kernel from one that had them all."""
    bench = load_script("bench_startup")
    said = tmp_path / "numba.txt"
    out = tmp_path / "out"
    environment = {bench.NUMBA_FILE: str(said), "CPR_KERNELS": mode}
    command = [sys.executable, "-c", bench.PROBED, "plan", str(paper_scene_path()), "--out", str(out)]
    bench.timed(command, bench.HERE, environment)
    assert (out / "trajectory.json").is_file()
    if imported is None:  # ahead: numba where no module for today's kernels was built, else not
        monkeypatch.setenv("CPR_KERNELS", mode)
        imported = str(not bench.kernels_ahead(bench.HERE))
    assert said.read_text() == imported
