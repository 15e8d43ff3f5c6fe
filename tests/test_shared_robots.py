"""A robot kept per thread while its files are unchanged (cpr_kin.description.shared_robots)."""

from __future__ import annotations

import os
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.description import shared_robots
from cpr_kin.model.packages import example_robot
from planning import load_scene, plan
from planning.bench.arm_scenes import blocked_scene
from planning.io.bundled import bundled_scene_paths
from planning.io.scene_file import parse_scene


@pytest.fixture(autouse=True)
def _nothing_kept() -> Iterator[None]:
    ck.forget_shared_robots()
    yield
    ck.forget_shared_robots()


@pytest.fixture
def arm(tmp_path: Path) -> ck.RobotSpec:
    """A copy of the CPR's URDF read by the generic rules, alone in its folder (no limits file)."""
    shutil.copy(ck.cpr_urdf_path(), tmp_path / "arm.urdf")
    return ck.RobotSpec(urdf=tmp_path / "arm.urdf")


def touch_later(path: Path) -> None:
    """Give ``path`` a modification time a second later than it had (a file system's clock is coarse)."""
    stamp = path.stat().st_mtime_ns + 1_000_000_000
    os.utime(path, ns=(stamp, stamp))


def test_the_same_thread_gets_the_same_robot_and_another_thread_its_own(arm: ck.RobotSpec) -> None:
    first = ck.shared_robot(arm)
    assert ck.shared_robot(arm) is first
    assert ck.shared_robot(ck.RobotSpec(urdf=arm.urdf)) is first  # an equal spec is the same robot
    other: list[ck.Robot] = []
    worker = threading.Thread(target=lambda: other.append(ck.shared_robot(arm)))
    worker.start()
    worker.join()
    assert other[0] is not first
    assert other[0].data is not first.data  # two threads never share the Pinocchio data
    assert ck.shared_robot(arm) is first


def test_a_changed_or_added_file_loads_the_robot_again(arm: ck.RobotSpec) -> None:
    first = ck.shared_robot(arm)
    assert "theta1" in first.limits_defaulted  # no limits file beside it yet
    limits = Path(arm.urdf).parent / "limits.yaml"
    limits.write_text("theta1: {velocity: 1.5, acceleration: 2.5, jerk: 12.0}\n")
    second = ck.shared_robot(arm)  # the folder changed: a limits file is looked for there
    assert second is not first
    assert second.limits.acceleration[0] == 2.5
    assert "theta1" not in second.limits_defaulted
    assert second.limits_path == limits
    limits.write_text("theta1: {velocity: 1.5, acceleration: 2.25, jerk: 12.0}\n")
    touch_later(limits)
    third = ck.shared_robot(arm)
    assert third is not second
    assert third.limits.acceleration[0] == 2.25
    touch_later(Path(arm.urdf))
    assert ck.shared_robot(arm) is not third
    assert ck.shared_robot(arm) is ck.shared_robot(arm)


def test_a_failed_load_keeps_nothing(arm: ck.RobotSpec) -> None:
    urdf = Path(arm.urdf)
    good = urdf.read_text()
    urdf.write_text("<robot name='broken'><link name='a'>")
    with pytest.raises(ck.UrdfError, match=r"arm\.urdf"):
        ck.shared_robot(arm)
    urdf.write_text(good)
    touch_later(urdf)
    robot = ck.shared_robot(arm)
    assert robot.joint_names == ck.CPR_JOINTS
    assert ck.shared_robot(arm) is robot


def test_a_robot_whose_urdf_changed_while_it_loaded_is_not_kept(
    arm: ck.RobotSpec, monkeypatch: pytest.MonkeyPatch
) -> None:
    load = ck.RobotSpec.load

    def edited_meanwhile(spec: ck.RobotSpec) -> ck.Robot:
        robot = load(spec)
        touch_later(Path(spec.urdf))  # an editor saved it after it was read
        return robot

    monkeypatch.setattr(ck.RobotSpec, "load", edited_meanwhile)
    first = ck.shared_robot(arm)
    monkeypatch.undo()
    second = ck.shared_robot(arm)
    assert second is not first  # read again
    assert ck.shared_robot(arm) is second


def test_at_most_the_kept_robots_stay(arm: ck.RobotSpec, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(shared_robots, "KEPT_ROBOTS", 1)
    first = ck.shared_robot(arm)
    cpr = ck.shared_robot(ck.cpr_spec())
    assert ck.shared_robot(ck.cpr_spec()) is cpr
    assert ck.shared_robot(arm) is not first  # dropped when the CPR came


def test_plan_without_a_robot_reuses_one_and_plans_as_a_fresh_robot_does() -> None:
    scene = load_scene(next(p for p in bundled_scene_paths() if p.stem == "shelf"))
    first, second = plan(scene), plan(scene)
    assert second.problem.robot is first.problem.robot
    fresh = plan(scene, ck.load_cpr())
    for result in (first, second):
        assert np.array_equal(result.trajectory.coefficients, fresh.trajectory.coefficients)
        assert np.array_equal(result.trajectory.knots, fresh.trajectory.knots)


def test_an_arm_of_meshes_reused_plans_to_the_bit_as_a_fresh_one(monkeypatch: pytest.MonkeyPatch) -> None:
    """The UR5's exact meshes learn near cells as it plans: what it keeps changes no plan."""
    ur5 = ck.load_robot(example_robot("ur5"))
    scenes = [parse_scene(blocked_scene(f"ur5_{seed}", "ur5", ur5, seed)) for seed in (0, 1)]
    loads: list[ck.RobotSpec] = []
    load = ck.RobotSpec.load

    def counted(spec: ck.RobotSpec) -> ck.Robot:
        loads.append(spec)
        return load(spec)

    monkeypatch.setattr(ck.RobotSpec, "load", counted)
    planned = [plan(scene) for scene in scenes + scenes]
    assert len(loads) == 1
    monkeypatch.undo()
    for scene, reused in zip(scenes + scenes, planned, strict=True):
        fresh = plan(scene, ck.load_robot(example_robot("ur5")))
        assert np.array_equal(reused.trajectory.coefficients, fresh.trajectory.coefficients)
