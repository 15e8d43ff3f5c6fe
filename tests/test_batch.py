from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from planning.batch import plan_batch, scene_files, summary_csv
from planning.cli import main
from planning.errors import PlanningError
from planning.io.bundled import paper_scene_path


@pytest.fixture(scope="module")
def scenes(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("scenes")
    paper = paper_scene_path().read_text()
    for seed in range(4):
        (folder / f"paper_{seed}.yaml").write_text(paper.replace("seed: 0", f"seed: {seed}"))
    (folder / "broken.yaml").write_text("start: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [2.0, 0.0, 0.3]}\n")
    (folder / "notes.txt").write_text("not a scene")
    return folder


def test_batch_local_processes(scenes: Path, tmp_path: Path) -> None:
    items = plan_batch(scene_files(scenes), tmp_path, workers=2)
    assert [i.scene for i in items] == ["broken", "paper_0", "paper_1", "paper_2", "paper_3"]
    broken = items[0]
    assert broken.status == "invalid" and broken.exit_class == 2 and "not reachable" in broken.message
    for item in items[1:]:
        assert item.status == "ok" and item.record is not None and item.record["min_clearance"] >= 0.1
        assert sorted(p.name for p in (tmp_path / item.scene).iterdir()) == [
            "report.md",
            "samples.csv",
            "trajectory.json",
        ]
    assert not (tmp_path / "broken").exists()
    rows = list(csv.DictReader(summary_csv(items).splitlines()))
    assert [r["status"] for r in rows] == ["invalid", "ok", "ok", "ok", "ok"]


def test_dask_cluster_gives_the_same_results(scenes: Path, tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    paths = scene_files(scenes)[1:3]
    local = plan_batch(paths, tmp_path / "local", workers=2)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        assert cluster.scheduler_address.startswith("tcp://127.0.0.1:")
        remote = plan_batch(paths, tmp_path / "dask", scheduler=cluster.scheduler_address)
    assert [i.scene for i in remote] == [i.scene for i in local]
    for a, b in zip(local, remote, strict=True):
        assert a.status == b.status == "ok" and a.record is not None and b.record is not None
        wall_times = ("planning_time_s", "optimiser_time_s")
        assert {k: v for k, v in a.record.items() if k not in wall_times} == {
            k: v for k, v in b.record.items() if k not in wall_times
        }
        assert (tmp_path / "local" / a.scene / "trajectory.json").read_bytes() == (
            tmp_path / "dask" / b.scene / "trajectory.json"
        ).read_bytes()


def test_bad_folders(tmp_path: Path) -> None:
    with pytest.raises(PlanningError, match="does not exist"):
        scene_files(tmp_path / "nowhere")
    with pytest.raises(PlanningError, match=r"holds no \.yaml scene files"):
        scene_files(tmp_path)
    with pytest.raises(PlanningError, match="cannot reach the Dask scheduler"):
        (tmp_path / "a.yaml").write_text("{}")
        plan_batch(scene_files(tmp_path), tmp_path / "out", scheduler="tcp://127.0.0.1:9")


def test_batch_command(scenes: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["batch", str(scenes), "--out", str(tmp_path), "--workers", "2"])
    out = capsys.readouterr().out
    assert code == 3  # one scene failed, the others were planned
    assert "4/5 scenes planned" in out and "broken (exit class 2)" in out
    assert (tmp_path / "summary.csv").exists()
    code = main(["batch", str(scenes), "--out", str(tmp_path / "j"), "--workers", "2", "--json"])
    result = json.loads(capsys.readouterr().out)
    assert code == 3 and result["ok"] == 4 and result["scenes"] == 5
    code = main(["batch", str(tmp_path / "missing"), "--out", str(tmp_path / "x")])
    assert code == 2 and "does not exist" in capsys.readouterr().err
