"""``scripts/bench_mbm.py``'s figures of OMPL's trajectories: the torques it reads from them."""

from __future__ import annotations

import sys
from pathlib import Path
from types import ModuleType, SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from tests.conftest import load_script

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_mbm.py"
SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


@pytest.fixture(scope="module")
def bench() -> ModuleType:
    return load_script("bench_mbm")


def test_the_torque_over_the_limit_is_pinocchio_s_rnea_along_the_trajectory(bench: ModuleType) -> None:
    robot = ck.load_robot(example_robot("ur5"))
    start = np.array([0.3, -1.2, 1.0, -0.5, 0.8, 0.1])
    acceleration = np.array([2.0, -3.0, 4.0, 1.0, -2.0, 3.0])  # [rad/s^2], uniform

    def timed(t: np.ndarray, order: int) -> np.ndarray:
        t = np.asarray(t)[:, None]
        values: list[np.ndarray] = [start + acceleration * t**2 / 2, acceleration * t, acceleration + 0 * t]
        return values[order]

    scene = SimpleNamespace(payload=None, torque_scale=0.5)
    usage = bench.torque_over_limit(scene, robot, timed, 0.4)
    model = robot.model
    data = model.createData()
    effort = 0.5 * model.effortLimit
    times = np.linspace(0.0, 0.4, 401)  # the same millisecond grid
    oracle = max(
        float(np.max(np.abs(pin.rnea(model, data, *(timed(np.array([t]), k)[0] for k in range(3)))) / effort))
        for t in times
    )
    assert usage == pytest.approx(oracle, rel=1e-9)


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--limit", "0"], "argument --limit: 0 must be an integer >= 1"),
        (["--limit", "101"], "--limit 101 must be in [1, 100] problems per class"),
        (["--sample-seed", "3"], "--sample-seed 3 goes with --limit"),
        (["--limit", "2", "--sample-seed", "-1"], "argument --sample-seed: -1 must be an integer >= 0"),
        (["--timeout", "0"], "argument --timeout: 0 must be a number > 0 s"),
    ],
)
def test_a_bad_sample_is_named_before_anything_runs(
    bench: ModuleType,
    arguments: list[str],
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    monkeypatch.setattr("sys.argv", ["bench_mbm.py", *arguments, "--out", str(tmp_path / "out")])
    with pytest.raises(SystemExit) as info:
        bench.main()
    assert info.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()  # nothing written


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (None, "does not exist"),
        ("foo: [\n", "is not valid YAML at line 2"),
        ("robot: {urdf: missing.urdf}", "missing.urdf"),  # the shelf with this robot
    ],
)
def test_a_bad_scene_file_is_named_before_anything_runs(
    bench: ModuleType,
    content: str | None,
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
) -> None:
    scene = tmp_path / "scene_1.yaml"
    if content is not None and content.startswith("robot:"):
        scene.write_text(SHELF.read_text().replace("robot: ../../urdf/cpr.urdf", content))
    elif content is not None:
        scene.write_text(content)
    monkeypatch.setattr("sys.argv", ["bench_mbm.py", "--scenes", str(scene), "--out", str(tmp_path / "out")])
    with pytest.raises(SystemExit) as info:
        bench.main()
    assert info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()  # nothing written


def test_a_scene_without_a_robot_is_the_cpr_s(bench: ModuleType, tmp_path: Path) -> None:
    text = "\n".join(line for line in SHELF.read_text().splitlines() if not line.startswith("robot:"))
    (tmp_path / "shelf.yaml").write_text(text + "\n")
    scene, robot = bench._robot(str(tmp_path / "shelf.yaml"))
    assert scene.robot == ck.cpr_spec()
    assert robot.limits.names == ck.load_cpr().limits.names


def test_the_peer_s_imports_are_done_before_its_first_timed_call() -> None:

    from planning.bench import import_peer

    import_peer()
    assert {"ompl.geometric", "toppra.algorithm", "toppra.constraint"} <= set(sys.modules)


def _beside_roboplan(scenes: Path, out: Path) -> tuple[str, dict[str, str], str]:
    """``bench_mbm.py --scenes scenes --peer roboplan`` run: its output, its one row and its table."""
    import csv
    import subprocess

    pytest.importorskip("roboplan.core", reason="the bench extra's roboplan")
    run = subprocess.run(
        [
            *(sys.executable, str(SCRIPT), "--scenes", str(scenes), "--peer", "roboplan"),
            *("--timeout", "10", "--out", str(out)),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    with (out / "mbm.csv").open() as rows:
        (row,) = list(csv.DictReader(rows))
    return run.stdout, row, (out / "mbm.md").read_text()


@pytest.mark.slow
def test_roboplan_runs_beside_ours_and_its_path_is_checked(tmp_path: Path) -> None:
    _, row, table = _beside_roboplan(SHELF, tmp_path / "bench")
    assert row["ours_ok"] == "True" and row["roboplan_ok"] == "True"
    assert 0 < float(row["roboplan_time_s"]) < 10 and float(row["roboplan_over_bound"]) > 0  # no jerk limit
    assert row["roboplan_checked"] in ("True", "False") and row["roboplan_clear"] in ("True", "False")
    assert "| roboplan paths failing `check` (touching) |" in table and "| scenes | all | 1 | 1 | 1 " in table


@pytest.mark.slow
def test_a_robot_the_peer_cannot_load_leaves_it_unsolved_with_the_reason_and_ours_stands(
    tmp_path: Path,
) -> None:
    """roboplan 0.7.0 refuses the Z1 of example-robot-data (a link and a joint share a frame name)."""
    import yaml

    from planning.bench.arm_scenes import blocked_scene

    robot = ck.load_robot(example_robot("z1"))
    scenes = tmp_path / "held"
    scenes.mkdir()
    (scenes / "z1_0.yaml").write_text(yaml.safe_dump(blocked_scene("z1_0", "z1", robot, seed=0)))
    output, row, table = _beside_roboplan(scenes, tmp_path / "bench")
    assert "roboplan could not run it (RuntimeError: " in output
    assert row["ours_ok"] == "True" and row["ours_checked"] == "True"
    assert row["roboplan_ok"] == "False" and row["roboplan_why"].startswith("RuntimeError: ")
    assert "| held | all | 1 | 1 | 0 " in table
