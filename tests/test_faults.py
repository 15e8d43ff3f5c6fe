"""Faults from outside: a plan killed at any step, two writers, a batch interrupted.

A reader of an output folder sees either nothing or one complete set (every file its
manifest lists, as written, from one run), whatever step a ``kill -9`` strikes. Each
process is signalled at a step it reaches (a count of its file operations, a lock file it
holds), not after a wall-clock delay.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from planning.io.bundled import bundled_scene_paths, paper_scene_path
from planning.io.publish import complete_set

pytestmark = pytest.mark.slow  # every test here starts processes

COMMAND = [sys.executable, "-m", "planning.cli"]
SHELF = next(p for p in bundled_scene_paths() if p.stem == "shelf")


def plan_process(scene: Path, out: Path, seed: int, *extra: str) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        [*COMMAND, "plan", str(scene), "--out", str(out), "--seed", str(seed), *extra],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )


KILLED_AT_STEP = """
import os
import shutil
import signal
import sys

import planning.io.publish as publish
from planning.cli.app import main

scene, out, step = sys.argv[1], sys.argv[2], int(sys.argv[3])
taken = 0


def counted(real):
    def step_then_real(*args, **kwargs):
        global taken
        taken += 1
        if taken == step:
            os.kill(os.getpid(), signal.SIGKILL)
        return real(*args, **kwargs)

    return step_then_real


publish._write = counted(publish._write)  # each file written
os.rename = counted(os.rename)  # each rename: a set aside, a set in, a set rolled back
shutil.rmtree = counted(shutil.rmtree)  # each removal: a leftover, the set replaced
sys.exit(main(["plan", scene, "--out", out, "--seed", str(step)]))
"""


def test_a_plan_killed_at_any_step_of_publishing_leaves_nothing_or_one_complete_set(tmp_path: Path) -> None:
    """``kill -9`` at every step of publishing and of tidying after a killed writer, in turn."""
    scene = tmp_path / "shelf.yaml"
    scene.write_bytes(SHELF.read_bytes())
    out = tmp_path / "out"
    assert plan_process(scene, out, 100).wait(timeout=120) == 0  # a previous set, seed 100
    seeds_seen, killed = set(), 0
    for step in range(1, 60):
        code = subprocess.run(
            [sys.executable, "-c", KILLED_AT_STEP, str(scene), str(out), str(step)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            timeout=120,
        ).returncode
        if out.exists():
            assert complete_set(out), f"step {step}: a partial or mixed set"
            seeds_seen.add(json.loads((out / "trajectory.json").read_text())["metrics"]["seed"])
        if code == 0:  # every step of this run came and went: all steps covered
            break
        assert code == -signal.SIGKILL
        killed += 1
    else:
        raise AssertionError("the plan never ran to its end")
    assert killed >= 8  # the files, the renames and the removals of a publication, at least
    assert 100 in seeds_seen and len(seeds_seen) > 1  # the previous set stayed whole, then was replaced
    # nothing the killed writers left remains
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "shelf.yaml"]


def test_a_second_plan_into_the_same_folder_is_refused(tmp_path: Path) -> None:
    slow = tmp_path / "slow.yaml"
    slow.write_text(paper_scene_path().read_text().replace("iterations: 50", "iterations: 2000"))
    first = plan_process(slow, tmp_path / "out", 0)
    try:
        deadline = time.monotonic() + 60
        while not (tmp_path / ".out.lock").exists() and time.monotonic() < deadline:
            time.sleep(0.01)
        second = subprocess.run(
            [*COMMAND, "plan", str(paper_scene_path()), "--out", str(tmp_path / "out")],
            capture_output=True,
            text=True,
            timeout=120,
        )
    finally:
        first.kill()
        first.wait()
    assert second.returncode == 2
    assert f"is being written by another cpr-plan (process {first.pid})" in second.stderr
    assert not (tmp_path / "out").exists()


def test_an_interrupted_background_batch_stops_and_summarises_the_scenes_done(tmp_path: Path) -> None:
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    paper = paper_scene_path().read_text()
    for seed in range(12):
        (scenes / f"paper_{seed:02d}.yaml").write_text(paper.replace("seed: 0", f"seed: {seed}"))
    out = tmp_path / "out"

    def as_a_background_job() -> None:  # a shell starts `cmd &` with SIGINT ignored
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    batch = subprocess.Popen(
        [*COMMAND, "batch", str(scenes), "--out", str(out), "--workers", "1"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=as_a_background_job,
    )
    deadline = time.monotonic() + 120
    # the second scene's files: one worker takes it only once the first scene's row is in (the
    # first scene's files alone may be published before its result reaches the dispatcher)
    while not (out / "paper_01" / "manifest.json").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    os.kill(batch.pid, signal.SIGINT)
    code = batch.wait(timeout=60)
    assert code in (130, -signal.SIGINT)  # see the test below
    assert batch.stderr is not None and "interrupted after" in batch.stderr.read().decode()
    rows = list(csv.DictReader((out / "summary.csv").read_text().splitlines()))
    assert 1 <= len(rows) < 12 and all(r["status"] == "ok" for r in rows)
    assert all(complete_set(out / r["scene"]) for r in rows)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_a_signalled_plan_exits_cleanly_writing_nothing(tmp_path: Path, signum: int) -> None:
    slow = tmp_path / "slow.yaml"
    slow.write_text(paper_scene_path().read_text().replace("iterations: 50", "iterations: 2000"))
    process = plan_process(slow, tmp_path / "out", 0)
    deadline = time.monotonic() + 60
    while not (tmp_path / ".out.lock").exists() and time.monotonic() < deadline:
        time.sleep(0.01)
    process.send_signal(signum)
    # 130, or death by SIGINT, which a shell reports as 130 too: CPython 3.11 re-raises SIGINT
    # at exit if the interrupt struck inside exec()'d code (dataclasses, numba), caught or not
    assert process.wait(timeout=30) in (130, -signal.SIGINT)
    assert process.stderr is not None and "interrupted; nothing written" in process.stderr.read().decode()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["slow.yaml"]
