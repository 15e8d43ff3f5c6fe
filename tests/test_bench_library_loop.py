"""``scripts/bench_library_loop.py``: a script's ``plan(load_scene(path))`` with the robot kept and loaded."""

from __future__ import annotations

import pytest

from .conftest import run_script, script_table


@pytest.mark.slow
def test_each_robot_gets_a_row_both_ways_and_the_same_trajectories() -> None:
    rows = script_table("bench_library_loop", "--robots", "cpr", "--scenes", "1", "--rounds", "2")
    assert rows[0] == [
        "robot",
        "scenes",
        "kept: median call [s]",
        "loaded each call: median [s]",
        "kept / loaded",
    ]
    (cpr,) = rows[1:]
    assert cpr[:2] == ["cpr", "1"]
    kept, loaded, ratio = (float(cell) for cell in cpr[2:])
    assert kept > 0 and loaded > 0
    # the times are printed to 1 ms and the ratio to 0.01: the ratio of the printed times is that close
    rounding = kept / loaded * (0.0005 / kept + 0.0005 / loaded) + 0.005
    assert ratio == pytest.approx(kept / loaded, abs=rounding + 1e-9)


def test_a_robot_it_does_not_know_is_refused_with_the_choices() -> None:
    done = run_script("bench_library_loop", "--robots", "r2d2", timeout_s=60)
    assert done.returncode == 2
    assert "argument --robots: invalid choice: 'r2d2'" in done.stderr
