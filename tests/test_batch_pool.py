"""A batch on a real Dask cluster whose worker runs in another folder, and the scheduler address checked.

The scheduler and the worker are started by the tests as the ``dask`` command line starts
them, the worker in a folder of its own; ``cpr-plan batch`` runs in a third folder with
relative paths, as a user types them.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

import cpr_kin as ck
from planning.batch import check_scheduler, check_workers, run_batch
from planning.cli import main
from planning.errors import PlanningError
from planning.io.bundled import bundled_scene_paths, paper_scene_path
from planning.io.publish import complete_set

DASK = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
WORKER = [sys.executable, "-m", "distributed.cli.dask_worker"]
CPR_PLAN = [sys.executable, "-m", "planning.cli"]


def wait_for(condition: object, what: str, seconds: float = 120.0) -> None:
    deadline = time.monotonic() + seconds
    while not condition():  # type: ignore[operator]
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.05)


def written_address(address_file: Path) -> str | None:
    """The scheduler's address from its file, ``None`` until the file is written whole.

    Dask creates the file before it writes it: a reader in between finds it empty.
    """
    try:
        return str(json.loads(address_file.read_text())["address"])
    except (FileNotFoundError, json.JSONDecodeError, KeyError):
        return None


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """A scheduler and one worker (two processes), the worker in a folder of its own."""
    home = tmp_path_factory.mktemp("cluster")
    worker_home = tmp_path_factory.mktemp("worker_home")
    address_file = home / "scheduler.json"
    quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
    scheduler = subprocess.Popen(
        [
            *DASK,
            "--host",
            "127.0.0.1",
            "--port",
            "0",
            "--no-dashboard",
            "--scheduler-file",
            str(address_file),
        ],
        cwd=home,
        **quiet,  # type: ignore[call-overload]
    )
    wait_for(lambda: written_address(address_file) is not None, "the scheduler's address file")
    address = written_address(address_file)
    assert address is not None
    worker = subprocess.Popen(
        [*WORKER, address, "--nworkers", "2", "--nthreads", "1", "--no-dashboard"],
        cwd=worker_home,
        **quiet,  # type: ignore[call-overload]
    )
    try:
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
        yield address
    finally:
        for process in (worker, scheduler):
            process.terminate()
            process.wait(timeout=60)
        assert sorted(p.name for p in worker_home.iterdir() if not p.name.startswith("dask-scratch")) == [], (
            "the worker wrote into its own folder"
        )


def user_folder(root: Path, count: int) -> Path:
    """A user's folder: ``scenes/`` with ``count`` shelf scenes, one using a URDF by a relative path."""
    scenes = root / "scenes"
    scenes.mkdir(parents=True)
    (scenes / "robots").mkdir()
    (scenes / "robots" / "cpr.urdf").write_bytes(ck.cpr_urdf_path().read_bytes())
    shelf = next(p for p in bundled_scene_paths() if p.stem == "shelf").read_text()
    for k in range(count):
        text = shelf.replace("seed: 3", f"seed: {k}")
        if k == 0:
            text = "robot: robots/cpr.urdf\n" + text.replace("robot:", "# robot:")
        (scenes / f"shelf_{k:02d}.yaml").write_text(text)
    return root


def rows(summary: Path) -> list[dict[str, str]]:
    return list(csv.DictReader(summary.read_text().splitlines()))


@pytest.mark.slow
def test_relative_paths_resolve_in_the_caller_on_a_cluster(cluster: str, tmp_path: Path) -> None:
    user = user_folder(tmp_path / "user", 3)
    done = subprocess.run(
        [*CPR_PLAN, "batch", "scenes", "--out", "out", "--scheduler", cluster],
        cwd=user,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    listed = rows(user / "out" / "summary.csv")
    assert [r["scene"] for r in listed] == ["shelf_00", "shelf_01", "shelf_02"]
    assert all(r["status"] == "ok" for r in listed)
    for row in listed:
        assert complete_set(user / "out" / row["scene"])
    recorded = json.loads((user / "out" / "shelf_00" / "trajectory.json").read_text())["robot"]
    assert recorded == str((user / "scenes" / "robots" / "cpr.urdf").resolve())


@pytest.mark.slow
def test_an_absolute_scene_folder_still_writes_under_the_callers_out(cluster: str, tmp_path: Path) -> None:
    user = user_folder(tmp_path / "user", 1)
    done = subprocess.run(
        [*CPR_PLAN, "batch", str(user / "scenes"), "--out", "results", "--scheduler", cluster],
        cwd=user,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert complete_set(user / "results" / "shelf_00")


@pytest.mark.slow
def test_an_interrupted_cluster_batch_lists_every_scene_that_finished(cluster: str, tmp_path: Path) -> None:
    user = user_folder(tmp_path / "user", 12)
    out = user / "out"
    batch = subprocess.Popen(
        [*CPR_PLAN, "batch", "scenes", "--out", "out", "--scheduler", cluster],
        cwd=user,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )

    def finished() -> list[str]:
        return [p.name for p in out.iterdir() if p.is_dir() and complete_set(p)] if out.exists() else []

    wait_for(lambda: len(finished()) >= 2, "two scenes published")
    os.kill(batch.pid, signal.SIGINT)
    _, stderr = batch.communicate(timeout=120)
    assert batch.returncode == 130 and "interrupted after" in stderr and "Traceback" not in stderr
    listed = {r["scene"] for r in rows(out / "summary.csv")}
    assert set(finished()) <= listed, "a scene whose outputs are complete is missing from the summary"
    assert 2 <= len(listed) < 12


@pytest.mark.parametrize(
    ("address", "message"),
    [
        ("notaurl", "'notaurl' is not a scheduler address; expected PROTOCOL://HOST:PORT"),
        ("tcp://256.1.1.1:99999", "the port must be in [1, 65535]"),
        ("tcp://256.1.1.1:8786", "'256.1.1.1' is not an IP address"),
        ("http://127.0.0.1:8786", "is not a scheduler address"),
        ("tcp://:8786", "is not a scheduler address"),
        ("tcp://bad_host!:8786", "is not a host name"),
        ("tcp://-bad:8786", "'-bad' is not a host name"),
        ("tcp://[::1", "is not a scheduler address"),
        ("tcp://127.0.0.1:8786/path", "is not a scheduler address"),
        ("tcp://user@127.0.0.1:8786", "is not a scheduler address"),
    ],
)
def test_a_malformed_scheduler_address_is_refused_at_once(address: str, message: str) -> None:
    with pytest.raises(PlanningError, match=message.replace("[", r"\[").replace("]", r"\]")):
        check_scheduler(address)


@pytest.mark.parametrize(
    "address", ["tcp://127.0.0.1:8786", "tls://scheduler.example.org:8786", "tcp://[::1]:8786"]
)
def test_a_well_formed_address_passes(address: str) -> None:
    check_scheduler(address)


@pytest.mark.parametrize(
    ("workers", "scheduler", "message"),
    [
        (0, None, r"workers = 0 must be an integer >= 1"),
        (-3, None, r"workers = -3 must be an integer >= 1"),
        (True, None, r"workers = True must be an integer >= 1"),
        (2, "tcp://127.0.0.1:8786", r"workers = 2 limits local processes; .*leave workers out"),
    ],
)
def test_a_count_of_workers_is_checked_before_anything_runs(
    tmp_path: Path, workers: Any, scheduler: str | None, message: str
) -> None:
    # 0 and -3 ran on every core and on one, and a count beside a scheduler was ignored
    with pytest.raises(PlanningError, match=message):
        run_batch([tmp_path / "a.yaml"], tmp_path / "out", workers=workers, scheduler=scheduler)
    assert not (tmp_path / "out").exists()
    check_workers(None, scheduler)
    check_workers(1, None)


def test_the_command_refuses_workers_with_a_scheduler_before_the_output_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "a.yaml").write_text(paper_scene_path().read_text())
    out = tmp_path / "out"
    command = ["batch", str(tmp_path / "scenes"), "--out", str(out), "--workers", "2"]
    assert main([*command, "--scheduler", "tcp://127.0.0.1:8786"]) == 2
    assert "leave workers out with a scheduler" in capsys.readouterr().err and not out.exists()
    with pytest.raises(SystemExit):  # argparse: exit 2, naming the option
        main(["batch", str(tmp_path / "scenes"), "--out", str(out), "--workers", "0"])
    assert "--workers" in capsys.readouterr().err and not out.exists()


@pytest.mark.slow
def test_the_command_exits_2_before_connecting(tmp_path: Path) -> None:
    (tmp_path / "scenes").mkdir()
    (tmp_path / "scenes" / "a.yaml").write_text(paper_scene_path().read_text())
    done = subprocess.run(
        [*CPR_PLAN, "batch", "scenes", "--out", "out", "--scheduler", "tcp://256.1.1.1:99999"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 2 and "the port must be in [1, 65535]" in done.stderr
    assert done.stderr.count("\n") == 1 and not (tmp_path / "out").exists()
