"""How far a link's hull reaches beyond its mesh: an analytic case, trimesh's distances, the command."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.model.hull_excess import SAMPLES, shape_excess
from cpr_kin.model.packages import example_robot, example_robot_data_share
from planning.cli import main

URDF = """<robot name="dumbbell">
  <link name="base"><collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>
  <link name="arm"><collision><geometry><box size="0.05 0.05 0.2"/></geometry></collision></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/><origin xyz="0 0 0.5"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="10"/></joint>
</robot>
"""


def test_the_hull_of_two_cubes_exceeds_them_by_half_their_gap(tmp_path: Path) -> None:
    # cubes of 0.1 m at x in [0, 0.1] and [0.3, 0.4]: their hull's face y = 0 runs across the gap,
    # its middle (x = 0.2) 0.1 m from either cube
    cubes = [trimesh.creation.box(extents=(0.1, 0.1, 0.1)) for _ in range(2)]
    cubes[0].apply_translation([0.05, 0.05, 0.05])
    cubes[1].apply_translation([0.35, 0.05, 0.05])
    dumbbell: trimesh.Trimesh = trimesh.util.concatenate(cubes)  # type: ignore[assignment]
    dumbbell.export(tmp_path / "dumbbell.stl")
    (tmp_path / "dumbbell.urdf").write_text(URDF.format(mesh=tmp_path / "dumbbell.stl"))
    base, arm = shape_excess(ck.load_robot(tmp_path / "dumbbell.urdf"))
    assert base.kind == "exact mesh" and base.mesh.endswith("dumbbell.stl")  # its hull is a bound only
    assert 0.1 - base.spacing_m <= base.bound_excess_m <= 0.1 + 1e-9 and base.excess_m == 0.0
    assert (arm.kind, arm.excess_m) == ("box", 0.0)


def test_coal_s_distances_are_trimesh_s() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    (forearm,) = [s for s in shape_excess(robot, samples=2000, seed=4) if s.link == "forearm_link"]
    mesh: trimesh.Trimesh = trimesh.load(forearm.mesh, force="mesh")  # type: ignore[assignment]
    hull = trimesh.Trimesh(vertices=mesh.vertices).convex_hull
    points = trimesh.sample.sample_surface(hull, 2000, seed=4)[0]
    distances = trimesh.proximity.ProximityQuery(mesh).on_surface(points)[1]  # type: ignore[no-untyped-call]
    assert forearm.bound_excess_m == pytest.approx(float(np.max(distances)), abs=1e-6)
    assert forearm.bound_excess_m > 0.02  # the UR forearm's hollow: why its hull would refuse what it can do
    assert (forearm.kind, forearm.excess_m) == ("exact mesh", 0.0)  # so its mesh decides


def test_primitives_are_exact() -> None:
    assert all(s.excess_m == 0.0 and s.mesh == "" for s in shape_excess(ck.load_cpr()))


def test_robot_info_reports_every_shape(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot-info", "ur5", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = ck.load_robot(example_robot("ur5"))
    assert [s["geometry"] for s in report["shapes"]] == [g.name for g in robot.geometries]
    assert [j["name"] for j in report["joints"]] == list(robot.joint_names)
    assert report["excess_samples"] == SAMPLES and report["srdf"].endswith("ur5.srdf")
    assert main(["robot-info", "cpr"]) == 0
    printed = capsys.readouterr().out
    assert "tool frame: tcp" in printed and "base (base_link): cylinder, exact" in printed


def test_robot_info_of_no_robot_is_one_line(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    assert main(["robot-info", str(tmp_path / "arm.urdf")]) == 2
    error = capsys.readouterr().err
    assert "arm.urdf" in error and len(error.strip().splitlines()) == 1 and "Traceback" not in error


def test_robot_info_of_a_branched_robot_names_its_tool_frame(capsys: pytest.CaptureFixture[str]) -> None:
    """Baxter's tree branches into two arms and a head: loaded only with its tool frame named,
    as a scene's ``robot: {urdf, tcp, srdf}`` would, the joints from its root to that frame planned."""
    share = example_robot_data_share()
    assert share is not None
    root = share / "example-robot-data" / "robots" / "baxter_description"
    urdf, srdf = root / "urdf" / "baxter.urdf", root / "srdf" / "baxter_manipulation.srdf"
    assert main(["robot-info", str(urdf)]) == 2
    assert "name the tool frame" in capsys.readouterr().err
    assert main(["robot-info", str(urdf), "--tcp", "left_gripper", "--srdf", str(srdf), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["tcp_frame"] == "left_gripper" and report["srdf"] == str(srdf)
    assert [j["name"] for j in report["joints"]] == [
        f"left_{j}" for j in ("s0", "s1", "e0", "e1", "w0", "w1", "w2")
    ]
