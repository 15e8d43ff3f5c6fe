"""``scripts/bench_clutter.py``: a plan alone, among boxes out of reach and in a room's cloud."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot

from .conftest import load_script, run_script


@pytest.mark.slow
def test_clutter_out_of_reach_changes_no_plan() -> None:
    """Every variant of a scene plans the same trajectory (the script says where durations differ)."""
    completed = run_script("bench_clutter", "--scenes", "2", "--runs", "1", "--boxes", "60")
    assert completed.returncode == 0, completed.stderr[-2000:]
    lines = completed.stdout.splitlines()
    rows = [line.split() for line in lines if line.startswith("panda_")]
    assert len(rows) == 2 and not any("differ" in line for line in lines)
    assert all(float(value) > 0 for row in rows for value in row[1:6])
    assert lines[-1].startswith("median ratio to alone: boxes ")


def test_the_clutter_is_out_of_reach_and_the_room_around_it() -> None:
    """Oracle: coal's distance from the robot's swept capsules (its reach in every configuration)."""
    from cpr_kin.bounds.obstacle_bounds import obstacle_arrays
    from cpr_kin.collision.robot_reach import pair_reach_distances
    from cpr_kin.collision.touch_links import checked_pairs

    bench = load_script("bench_clutter")
    robot = ck.load_robot(example_robot("panda"))
    reach = bench.reach_m(robot)
    assert 1.0 < reach < 2.0  # the Panda reaches about 0.86 m from its shoulder, 1.19 m up
    clutter = bench.boxes(20, reach, 0)
    assert np.all(pair_reach_distances(robot, clutter, checked_pairs(robot, clutter)) > 0.0)
    blocks = bench.room(reach)
    walls = [o for o, centre in zip(blocks, obstacle_arrays(blocks).centre, strict=True) if centre[2] > 0.15]
    assert walls and np.all(pair_reach_distances(robot, walls, checked_pairs(robot, walls)) > 0.0)
