"""A robot's geometry model kept on disk: read back the same as built, rebuilt where anything changed."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.description import geometry_cache
from cpr_kin.description.geometry_cache import geometry_model, mesh_hull
from cpr_kin.model.packages import example_robot_data_share
from tests.test_exact_meshes import bvh_of

URDF = """<robot name="two">
  <link name="base"><collision><geometry><mesh filename="{base}"/></geometry></collision></link>
  <link name="arm">
    <collision><origin xyz="0 0 0.2"/>
      <geometry><mesh filename="{arm}" scale="0.5 0.5 0.5"/></geometry></collision>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
</robot>"""


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache" / "geometry-models"


def two_links(folder: Path) -> str:
    """The text of a two-link URDF whose links are meshes written into ``folder``."""
    trimesh.creation.icosphere(subdivisions=3, radius=0.1).export(folder / "base.stl")
    trimesh.creation.capsule(height=0.3, radius=0.05).export(folder / "arm.stl")
    return URDF.format(base=folder / "base.stl", arm=folder / "arm.stl")


def built(xml: str) -> tuple[Any, Any]:
    """The kinematic model and the collision model of ``xml`` as Pinocchio builds them."""
    model = pin.buildModelFromXML(xml)
    return model, pin.buildGeomFromUrdfString(model, xml, pin.GeometryType.COLLISION)


def corner_indices(bvh: Any) -> list[tuple[int, int, int]]:
    """Each triangle's vertex indices (coal hands them out one by one)."""
    return [(t[0], t[1], t[2]) for t in (bvh.tri_indices(i) for i in range(bvh.num_tris))]


def assert_same(found: Any, expected: Any) -> None:
    """Every object of two geometry models alike: frames, placements, meshes and coal's distances."""
    assert found.ngeoms == expected.ngeoms
    points = np.random.default_rng(7).uniform(-0.4, 0.4, (20, 3))
    for a, b in zip(found.geometryObjects, expected.geometryObjects, strict=True):
        assert (a.name, a.parentJoint, a.parentFrame, a.meshPath) == (
            b.name,
            b.parentJoint,
            b.parentFrame,
            b.meshPath,
        )
        np.testing.assert_array_equal(a.placement.homogeneous, b.placement.homogeneous)
        np.testing.assert_array_equal(a.meshScale, b.meshScale)
        assert type(a.geometry) is type(b.geometry)
        if not isinstance(b.geometry, coal.BVHModelBase):
            continue
        np.testing.assert_array_equal(a.geometry.vertices(), b.geometry.vertices())
        assert a.geometry.num_tris == b.geometry.num_tris
        assert corner_indices(a.geometry) == corner_indices(b.geometry)
        ball, request = coal.Sphere(0.01), coal.DistanceRequest()
        for point in points:  # the bounding-volume trees answer alike: the same distances, to the bit
            at = coal.Transform3s(np.eye(3), point)
            distances = [
                coal.distance(g, coal.Transform3s(), ball, at, request, coal.DistanceResult())
                for g in (a.geometry, b.geometry)
            ]
            assert distances[0] == distances[1]


def test_a_kept_model_reads_back_as_built_and_is_not_built_again(
    tmp_path: Path, own_cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    xml = two_links(tmp_path)
    model, expected = built(xml)
    first = geometry_model(model, xml, pin.GeometryType.COLLISION)
    assert len(list(own_cache.glob("*.bin"))) == 1
    monkeypatch.setattr(pin, "buildGeomFromUrdfString", lambda *_: pytest.fail("built again"))
    again = geometry_model(model, xml, pin.GeometryType.COLLISION)
    assert_same(first, expected)
    assert_same(again, expected)


def test_a_changed_mesh_or_scale_builds_anew(tmp_path: Path, own_cache: Path) -> None:
    xml = two_links(tmp_path)
    model, _ = built(xml)
    geometry_model(model, xml, pin.GeometryType.COLLISION)
    trimesh.creation.capsule(height=0.4, radius=0.05).export(tmp_path / "arm.stl")  # the same path
    _, expected = built(xml)
    assert_same(geometry_model(model, xml, pin.GeometryType.COLLISION), expected)
    rescaled = xml.replace('scale="0.5 0.5 0.5"', 'scale="0.6 0.6 0.6"')
    _, expected = built(rescaled)
    assert_same(geometry_model(model, rescaled, pin.GeometryType.COLLISION), expected)
    assert len(list(own_cache.glob("*.bin"))) == 3


@pytest.mark.parametrize("damage", [b"", b"\x16\x00\x00\x00\x00\x00\x00\x00serialization::archive", b"cut"])
def test_a_damaged_file_is_built_again_and_replaced(tmp_path: Path, own_cache: Path, damage: bytes) -> None:
    xml = two_links(tmp_path)
    model, expected = built(xml)
    geometry_model(model, xml, pin.GeometryType.COLLISION)
    (kept,) = own_cache.glob("*.bin")
    whole = kept.read_bytes()
    kept.write_bytes(damage if damage != b"cut" else whole[: len(whole) // 2])
    assert_same(geometry_model(model, xml, pin.GeometryType.COLLISION), expected)
    assert kept.read_bytes() == whole


def test_a_model_of_another_robot_under_the_name_is_not_read(tmp_path: Path, own_cache: Path) -> None:
    xml = two_links(tmp_path)
    model, expected = built(xml)
    geometry_model(model, xml, pin.GeometryType.COLLISION)
    (kept,) = own_cache.glob("*.bin")
    one = xml.replace('<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>', "")
    _, other = built(one)
    other.saveToBinary(str(kept))  # a model that does not fit the URDF: one object fewer
    assert_same(geometry_model(model, xml, pin.GeometryType.COLLISION), expected)


def test_models_beyond_the_kept_bytes_go_the_least_recently_used_first(
    tmp_path: Path, own_cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    xml = two_links(tmp_path)
    model, _ = built(xml)
    scaled = [xml.replace('scale="0.5 0.5 0.5"', f'scale="{s} {s} {s}"') for s in ("0.5", "0.6", "0.7")]
    geometry_model(model, scaled[0], pin.GeometryType.COLLISION)
    first = next(own_cache.glob("*.bin"))
    monkeypatch.setattr(geometry_cache, "KEPT_BYTES", int(2.5 * first.stat().st_size))  # two of them
    geometry_model(model, scaled[1], pin.GeometryType.COLLISION)
    second = (set(own_cache.glob("*.bin")) - {first}).pop()
    stamp = second.stat().st_mtime
    os.utime(second, (stamp - 100, stamp - 100))  # the second used long ago
    geometry_model(model, scaled[0], pin.GeometryType.COLLISION)  # the first read: just used
    geometry_model(model, scaled[2], pin.GeometryType.COLLISION)
    kept = set(own_cache.glob("*.bin"))
    assert len(kept) == 2 and first in kept and second not in kept


def test_a_robot_without_meshes_keeps_nothing(own_cache: Path) -> None:
    ck.load_cpr()
    assert not own_cache.exists() or not list(own_cache.glob("*.bin"))


def test_a_robot_loaded_from_its_kept_model_is_the_robot_built() -> None:
    share = example_robot_data_share()
    assert share is not None
    urdf = share / "example-robot-data" / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"
    built_robot = ck.load_robot(urdf)
    kept_robot = ck.load_robot(urdf)  # read from the disk
    assert_same(kept_robot.collision_model, built_robot.collision_model)
    assert kept_robot.exact_meshes.keys() == built_robot.exact_meshes.keys()
    configurations = np.random.default_rng(3).uniform(-1.0, 1.0, (50, built_robot.nq))
    world = [ck.CollisionWorld(r, []) for r in (built_robot, kept_robot)]
    built_distances, kept_distances = (w.self_collision.distances(configurations)[0] for w in world)
    np.testing.assert_array_equal(kept_distances, built_distances)


def test_a_meshs_hull_is_kept_and_reads_back_as_qhull_builds_it(own_cache: Path) -> None:
    mesh = trimesh.creation.capsule(height=0.3, radius=0.05)
    built_bvh, kept_bvh = bvh_of(mesh), bvh_of(mesh)
    built_bvh.buildConvexHull(True, "Qt")
    first = mesh_hull(bvh_of(mesh), True, "Qt")
    (kept,) = (own_cache.parent / "mesh-hulls").glob("*.bin")
    again = mesh_hull(kept_bvh, True, "Qt")
    assert kept_bvh.convex is None  # read from the disk, not built
    ball, request = coal.Sphere(0.01), coal.DistanceRequest()
    for hull in (first, again):
        assert isinstance(hull, coal.Convex) and hull.num_points == built_bvh.convex.num_points
        for point in np.random.default_rng(5).uniform(-0.3, 0.3, (20, 3)):
            at = coal.Transform3s(np.eye(3), point)
            distances = [
                coal.distance(h, coal.Transform3s(), ball, at, request, coal.DistanceResult())
                for h in (hull, built_bvh.convex)
            ]
            assert distances[0] == distances[1]
    kept.write_bytes(kept.read_bytes()[:100])  # cut short: built again
    assert mesh_hull(bvh_of(mesh), True, "Qt").num_points == built_bvh.convex.num_points
    assert kept.stat().st_size > 100
