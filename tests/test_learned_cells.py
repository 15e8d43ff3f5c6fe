"""The near cells' memory kept on disk: read back by the next process, never another robot's, merged."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.collision import learned_cells
from cpr_kin.collision.near_cells import NearCells
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.common.disk_cache import read_array, write_array
from planning.bench.mbm import vamp_resources


@pytest.fixture(scope="module")
def ur5() -> ck.Robot:
    """MotionBenchMaker's UR5 (vamp-planner's, cached): its near pairs have concave links' meshes."""
    return ck.load_robot(vamp_resources("ur5") / "ur5.urdf", srdf=vamp_resources("ur5") / "ur5.srdf")


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def near_pairs(robot: ck.Robot) -> list[tuple[int, int]]:
    self_collision = ck.CollisionWorld(robot, [], self_margin_m=0.001).self_collision
    screen = self_collision._screen
    assert screen is not None
    return [p for p, near in zip(self_collision._pairs, screen.near, strict=True) if near]


def cells_of(robot: ck.Robot, pairs: list[tuple[int, int]], kept: bool = True) -> NearCells:
    return NearCells(robot.model, robot.collision_model, pairs, robot_reach(robot), robot.exact_meshes, kept)


def configurations(robot: ck.Robot, seed: int, count: int = 400) -> np.ndarray:
    return np.random.default_rng(seed).uniform(robot.limits.lower, robot.limits.upper, (count, robot.nq))


def test_what_one_memory_learned_the_next_starts_with_and_answers_alike(ur5: ck.Robot, folder: Path) -> None:
    pairs = near_pairs(ur5)
    q, margins = configurations(ur5, 1), [0.001] * len(pairs)
    first = cells_of(ur5, pairs)
    assert first.memory.digest is not None
    cleared = {kind: first.clear(q, margins, on_meshes=kind) for kind in (False, True)}
    assert first.tested > 0 and cleared[True].sum() > cleared[False].sum()
    first.memory.save()
    assert (folder / "near-cells" / f"{first.memory.digest}.npy").is_file()
    second = cells_of(ur5, pairs)
    for kind in (False, True):
        np.testing.assert_array_equal(second.clear(q, margins, on_meshes=kind), cleared[kind])
    assert second.tested == 0  # every answer from the memory read
    # the answers are those of cells that keep nothing (coal's, as the cells' own tests check)
    unkept = cells_of(ur5, pairs, kept=False)
    assert unkept.memory.digest is None
    for kind in (False, True):
        np.testing.assert_array_equal(unkept.clear(q, margins, on_meshes=kind), cleared[kind])
    assert unkept.tested == first.tested


def test_another_robots_or_a_damaged_memory_is_not_read(ur5: ck.Robot, folder: Path) -> None:
    pairs = near_pairs(ur5)
    q, margins = configurations(ur5, 2), [0.001] * len(pairs)
    kept = cells_of(ur5, pairs)
    kept.clear(q, margins, on_meshes=True)
    kept.memory.save()
    # one pair of the two: other cells, another digest, nothing read
    alone = cells_of(ur5, pairs[:1])
    assert alone.memory.digest != kept.memory.digest
    alone.clear(q, margins[:1], on_meshes=True)
    assert alone.tested > 0
    digest = kept.memory.digest
    assert digest is not None
    size = kept.grids.size  # type: ignore[union-attr]
    nan = np.full((6, size), np.nan, dtype=np.float32)
    for damaged in (np.zeros((6, 3), dtype=np.float32), np.zeros((6, size)), nan):
        write_array("near-cells", digest, damaged)
        again = cells_of(ur5, pairs)
        again.clear(q, margins, on_meshes=True)
        assert again.tested == kept.tested  # learned anew
    (folder / "near-cells" / f"{digest}.npy").write_bytes(b"\x93NUMPY cut short")
    assert read_array("near-cells", digest) is None
    again = cells_of(ur5, pairs)
    again.clear(q, margins, on_meshes=True)
    assert again.tested == kept.tested


def test_two_memories_kept_at_once_both_stay(ur5: ck.Robot, folder: Path) -> None:
    pairs = near_pairs(ur5)
    margins = [0.001] * len(pairs)
    q_one, q_two = configurations(ur5, 3), configurations(ur5, 4)
    one, two = cells_of(ur5, pairs), cells_of(ur5, pairs)  # two processes started together
    one.clear(q_one, margins, on_meshes=True)
    two.clear(q_two, margins, on_meshes=True)
    one.memory.save()
    two.memory.save()  # merged with what the first kept
    both = cells_of(ur5, pairs)
    both.clear(np.concatenate([q_one, q_two]), margins, on_meshes=True)
    assert both.tested == 0


def test_learning_is_kept_once_it_adds_up(
    ur5: ck.Robot, folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pairs = near_pairs(ur5)
    margins = [0.001] * len(pairs)
    monkeypatch.setattr(learned_cells, "SAVE_AFTER_S", 1e9)
    cells = cells_of(ur5, pairs)
    cells.clear(configurations(ur5, 5), margins, on_meshes=True)
    assert cells.tested > 0 and cells.memory.digest is not None
    assert read_array("near-cells", cells.memory.digest) is None  # not yet: kept at the process's end
    monkeypatch.setattr(learned_cells, "SAVE_AFTER_S", 0.0)
    cells.clear(configurations(ur5, 6), margins, on_meshes=True)
    kept = read_array("near-cells", cells.memory.digest)
    assert kept is not None and kept.shape == (6, cells.grids.size)  # type: ignore[union-attr]
    for found, known in zip(kept[3:], cells.memory.kinds[True].arrays(), strict=True):
        np.testing.assert_array_equal(found, known)


def test_old_memories_go_beyond_the_kept_bytes(
    ur5: ck.Robot, folder: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    old = folder / "near-cells" / "an-older-version.npy"
    old.parent.mkdir(parents=True)
    np.save(old, np.zeros(1000, dtype=np.float32))  # another version's memory, never read again
    monkeypatch.setattr(learned_cells, "KEPT_BYTES", 1)  # below any one memory: the one kept stays alone
    monkeypatch.setattr(learned_cells, "SAVE_AFTER_S", 1e9)  # kept by the save below, however slow the cells
    pairs = near_pairs(ur5)
    cells = cells_of(ur5, pairs)
    cells.clear(configurations(ur5, 7), [0.001] * len(pairs), on_meshes=True)
    cells.memory.save()
    assert [p.name for p in (folder / "near-cells").iterdir()] == [f"{cells.memory.digest}.npy"]


@pytest.mark.slow
@pytest.mark.parametrize("ending", ["", "from planning.cli.process import end_process; end_process(0)\n"])
def test_a_new_process_reads_what_an_ended_one_learned(folder: Path, ending: str) -> None:
    # the digest is the same in another process, and the memory is kept when a process ends:
    # through Python's exit functions, or cpr-plan's end (which skips them), below the time
    # that keeps it at once
    script = (
        "import sys, numpy as np, cpr_kin as ck\n"
        "from planning.bench.mbm import vamp_resources\n"
        "import cpr_kin.collision.learned_cells as kept\n"
        "kept.SAVE_AFTER_S = 1e9\n"
        "r = vamp_resources('ur5')\n"
        "robot = ck.load_robot(r / 'ur5.urdf', srdf=r / 'ur5.srdf')\n"
        "world = ck.CollisionWorld(robot, [], self_margin_m=0.001)\n"
        "q = np.random.default_rng(7).uniform(robot.limits.lower, robot.limits.upper, (300, robot.nq))\n"
        "world.self_collision.violated(q, 0.001)\n"
        "cells = world.self_collision._screen.near_cells\n"
        "print(cells.memory.digest, cells.tested, flush=True)\n"
    ) + ending
    env = {"CPR_FIREFLY_CACHE": str(folder), "PATH": ""}
    command = [sys.executable, "-c", script]
    runs = [subprocess.run(command, capture_output=True, text=True, env=env) for _ in range(2)]
    assert all(run.returncode == 0 for run in runs), runs[0].stderr + runs[1].stderr
    (digest_one, tested_one), (digest_two, tested_two) = (run.stdout.split() for run in runs)
    assert digest_one == digest_two and int(tested_one) > 0 and int(tested_two) == 0
