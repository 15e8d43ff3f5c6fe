from __future__ import annotations

import csv
import json
import os
import signal
from pathlib import Path

import pytest

from planning.batch import BatchItem, plan_scene_file, run_batch, scene_files, summary_csv
from planning.cli import main
from planning.errors import PlanningError
from planning.io.bundled import paper_scene_path
from planning.io.publish import complete_set
from planning.pipeline.metrics import WALL_TIMES


@pytest.fixture(scope="module")
def scenes(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("scenes")
    paper = paper_scene_path().read_text()
    for seed in range(4):
        (folder / f"paper_{seed}.yaml").write_text(paper.replace("seed: 0", f"seed: {seed}"))
    (folder / "broken.yaml").write_text(
        "start: {tcp: [0.5, 0.45, 0.25]}\ngoal: {q: [0.0, 0.9, 0.3, 0.0, 0.0]}\n"
    )
    (folder / "notes.txt").write_text("not a scene")
    return folder


@pytest.mark.slow
def test_batch_local_processes(scenes: Path, tmp_path: Path) -> None:
    run = run_batch(scene_files(scenes), tmp_path, workers=2)
    items = run.items
    assert not run.interrupted
    assert [i.scene for i in items] == ["broken", "paper_0", "paper_1", "paper_2", "paper_3"]
    broken = items[0]
    assert (
        broken.status == "invalid"
        and broken.exit_class == 2
        and "joint 'd2' = 0.9 m is outside" in broken.message
    )
    for item in items[1:]:
        assert item.status == "ok" and item.record is not None and item.record["min_clearance"] >= 0.1
        assert complete_set(tmp_path / item.scene)
        assert sorted(p.name for p in (tmp_path / item.scene).iterdir()) == [
            "manifest.json",
            "report.md",
            "samples.csv",
            "trajectory.json",
        ]
    assert not (tmp_path / "broken").exists()
    rows = list(csv.DictReader(summary_csv(items).splitlines()))
    assert [r["status"] for r in rows] == ["invalid", "ok", "ok", "ok", "ok"]


def die_on_doomed(path: Path, out: Path) -> BatchItem:
    """A scene task whose worker dies (as in a segfault) on the scene named 'doomed'."""
    if path.stem == "doomed":
        os.kill(os.getpid(), signal.SIGKILL)
    return plan_scene_file(path, out)


def raise_on_doomed(path: Path, out: Path) -> BatchItem:
    """A scene task that fails outside plan_scene_file's own handling (a bug in the pool's path)."""
    if path.stem == "doomed":
        raise MemoryError("out of memory while planning")
    return plan_scene_file(path, out)


@pytest.mark.slow
def test_a_worker_that_dies_sinks_only_its_scene(scenes: Path, tmp_path: Path) -> None:
    folder = tmp_path / "scenes"
    folder.mkdir()
    for path in scene_files(scenes)[1:4]:
        (folder / path.name).write_bytes(path.read_bytes())
    (folder / "doomed.yaml").write_bytes((scenes / "paper_0.yaml").read_bytes())
    run = run_batch(scene_files(folder), tmp_path / "out", workers=2, task=die_on_doomed)
    statuses = {item.scene: (item.status, item.exit_class) for item in run.items}
    assert statuses == {
        "doomed": ("crashed", 4),
        "paper_0": ("ok", 0),
        "paper_1": ("ok", 0),
        "paper_2": ("ok", 0),
    }
    rows = {r["scene"]: r for r in csv.DictReader(summary_csv(run.items).splitlines())}
    assert rows["doomed"]["status"] == "crashed" and "worker process died" in rows["doomed"]["message"]
    assert all(complete_set(tmp_path / "out" / name) for name in ("paper_0", "paper_1", "paper_2"))
    # an exception outside the task's own handling is that scene's row too
    run = run_batch(scene_files(folder), tmp_path / "again", workers=2, task=raise_on_doomed)
    doomed = next(i for i in run.items if i.scene == "doomed")
    assert (doomed.status, doomed.message) == ("error", "MemoryError: 'out of memory while planning'")
    assert sum(i.status == "ok" for i in run.items) == 3


def test_an_unexpected_exception_in_a_scene_is_its_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import planning.pipeline.planner

    def broken_plan(*args: object, **kwargs: object) -> None:
        raise IndexError("index 7 is out of bounds for axis 0 with size 5")

    monkeypatch.setattr(planning.pipeline.planner, "plan", broken_plan)
    item = plan_scene_file(paper_scene_path(), tmp_path / "paper")
    assert (item.status, item.exit_class) == ("error", 4)
    assert item.message == "IndexError: index 7 is out of bounds for axis 0 with size 5"
    assert item.record is None
    assert not (tmp_path / "paper").exists()


def test_a_scene_never_replaces_a_folder_that_is_not_ours(tmp_path: Path) -> None:
    scene = tmp_path / "odd.yaml"
    scene.write_text((paper_scene_path()).read_text())
    out = tmp_path / "odd"
    out.mkdir()
    (out / "keep.txt").write_text("the user's file")  # a folder that is not ours: refused, not replaced
    item = plan_scene_file(scene, out)
    assert item.status == "invalid" and "holds files a plan does not write (keep.txt)" in item.message
    assert (out / "keep.txt").read_text() == "the user's file"


@pytest.mark.slow
def test_dask_cluster_gives_the_same_results(scenes: Path, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    paths = scene_files(scenes)[1:3]
    local = run_batch(paths, tmp_path / "local", workers=2).items
    with distributed.LocalCluster(  # one worker, two threads: two scenes at once in one process
        n_workers=1, threads_per_worker=2, processes=True, dashboard_address=None
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = run_batch(paths, tmp_path / "dask", scheduler=cluster.scheduler_address).items
    assert [i.scene for i in remote] == [i.scene for i in local]
    for a, b in zip(local, remote, strict=True):
        assert a.status == b.status == "ok" and a.record is not None and b.record is not None
        wall_times = WALL_TIMES
        assert {k: v for k, v in a.record.items() if k not in wall_times} == {
            k: v for k, v in b.record.items() if k not in wall_times
        }
        assert (tmp_path / "local" / a.scene / "trajectory.json").read_bytes() == (
            tmp_path / "dask" / b.scene / "trajectory.json"
        ).read_bytes()


@pytest.mark.slow
def test_bad_folders(tmp_path: Path) -> None:
    with pytest.raises(PlanningError, match="does not exist"):
        scene_files(tmp_path / "nowhere")
    with pytest.raises(PlanningError, match=r"holds no \.yaml scene files"):
        scene_files(tmp_path)
    with pytest.raises(PlanningError, match="cannot reach the Dask scheduler"):
        (tmp_path / "a.yaml").write_text("{}")
        run_batch(scene_files(tmp_path), tmp_path / "out", scheduler="tcp://127.0.0.1:9")


@pytest.mark.slow
def test_batch_command(scenes: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["batch", str(scenes), "--out", str(tmp_path / "b"), "--workers", "2"])
    out = capsys.readouterr().out
    assert code == 2  # the worst class: one scene was invalid, the others were planned
    assert "4/5 scenes planned" in out and "broken (exit class 2)" in out
    assert (tmp_path / "b" / "summary.csv").exists()
    code = main(["batch", str(scenes), "--out", str(tmp_path / "j"), "--workers", "2", "--json"])
    result = json.loads(capsys.readouterr().out)
    assert code == 2 and result["ok"] == 4 and result["scenes"] == 5 and not result["interrupted"]
    code = main(["batch", str(tmp_path / "missing"), "--out", str(tmp_path / "x")])
    assert code == 2 and "does not exist" in capsys.readouterr().err
    (tmp_path / "file").write_text("")
    code = main(["batch", str(scenes), "--out", str(tmp_path / "file")])
    assert code == 2 and "output folder" in capsys.readouterr().err and (tmp_path / "file").read_text() == ""


def test_a_row_about_a_long_path_says_what_is_wrong(tmp_path: Path) -> None:
    """The row's message is one line, cut as the CLI's errors are: not before a long path has left room."""
    deep = tmp_path.joinpath(*["folder_" * 20] * 4)  # 560 characters below tmp_path
    deep.mkdir(parents=True)
    scene = deep / "odd.yaml"
    scene.write_text(paper_scene_path().read_text())
    out = deep / "odd"
    out.mkdir()
    (out / "keep.txt").write_text("the user's file")
    item = plan_scene_file(scene, out)
    assert item.status == "invalid" and len(item.message) <= 1000 and "\n" not in item.message
    assert item.message.endswith("holds files a plan does not write (keep.txt); name a new or empty folder")


def test_a_task_scene_is_planned_as_plan_plans_it(tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text(
        "start: {tcp: [0.6, -0.2, 0.3]}\n"
        "task:\n  - move: {tcp: [-0.1, 0.55, 0.45]}\n  - wait: 0.2\n"
        "  - line: {by: [0, 0, -0.05], frame: base}\n"
        "obstacles:\n  - {name: crate, shape: box, size: [0.2, 0.2, 0.3], xyz: [0.35, 0.35, 0.15]}\n"
    )
    item = plan_scene_file(task, tmp_path / "out" / "task")
    assert item.status == "ok" and item.record is not None, item.message
    assert item.record["segments"] == 3 and item.record["min_clearance"] >= 0.1
    written = json.loads((tmp_path / "out" / "task" / "trajectory.json").read_text())
    assert [entry["kind"] for entry in written["task"]] == ["free", "wait", "line"]
    assert written["metrics"]["duration"] == pytest.approx(item.record["duration"])
    assert main(["check", str(task), str(tmp_path / "out" / "task" / "trajectory.json")]) == 0  # the oracle
    (row,) = csv.DictReader(summary_csv([item]).splitlines())
    assert row["status"] == "ok" and row["duration"] and row["t_sol"] == "" and row["evaluations"] == ""


def test_scene_files_take_either_suffix_in_any_case(tmp_path: Path) -> None:
    for name in ("b.YAML", "a.yml", "c.Yaml", "notes.txt", "d.yaml.bak"):
        (tmp_path / name).write_text("{}")
    (tmp_path / "folder.yaml").mkdir()
    assert [p.name for p in scene_files(tmp_path)] == ["a.yml", "b.YAML", "c.Yaml"]
