"""A mesh's convex pieces: every triangle held, a distance never above the mesh's, read from disk."""

from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin.shapes.mesh_pieces as mesh_pieces_module
from cpr_kin.model.packages import example_robot_data_share
from cpr_kin.shapes.coal_queries import COLLIDE_MARGIN_AT_LEAST_M
from cpr_kin.shapes.mesh_geometry import convex_hull
from cpr_kin.shapes.mesh_pieces import CUTS, Side, convex_pieces, mesh_pieces, pieces_apart, sides_apart
from tests.test_exact_meshes import bvh_of, l_shape

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
UR10_FOREARM = SHARE / "example-robot-data" / "robots" / "ur_description" / "meshes" / "ur10" / "collision"


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))


def forearm() -> trimesh.Trimesh:
    """The UR10's forearm collision mesh: a concave link whose hull exceeds it by 4 cm."""
    loaded = trimesh.load(UR10_FOREARM / "forearm.stl", force="mesh")
    assert isinstance(loaded, trimesh.Trimesh)
    return loaded


@pytest.mark.parametrize("mesh", [l_shape(), forearm()], ids=["L", "UR10 forearm"])
def test_every_triangle_has_its_corners_in_one_piece(mesh: trimesh.Trimesh) -> None:
    triangles = np.asarray(mesh.triangles)
    pieces = mesh_pieces(triangles)
    assert 2 <= len(pieces) <= 2**CUTS
    held = np.zeros(len(triangles), dtype=bool)
    for corners in pieces:
        known = {tuple(point) for point in corners.tolist()}
        held |= [all(tuple(corner) in known for corner in triangle.tolist()) for triangle in triangles]
    assert held.all()


def test_the_ls_pieces_leave_its_notch_empty() -> None:
    # the notch (x, y in [0.5, 1]) lies in the L's hull; (0.7, 0.7) is 0.2 m from the L, and
    # about as far from every piece
    notch = coal.Sphere(1e-3), coal.Transform3s(np.eye(3), np.array([0.7, 0.7, 0.05]))
    hull = convex_hull(l_shape().vertices)
    assert _distance(hull, *notch) < 0.0  # the hull holds it
    pieces = convex_pieces(np.asarray(l_shape().triangles))
    assert min(_distance(piece, *notch) for piece in pieces) > 0.19


def test_the_pieces_distance_is_at_most_the_meshs_and_keeps_the_margin() -> None:
    mesh = forearm()
    pieces, bvh, at = convex_pieces(np.asarray(mesh.triangles)), bvh_of(mesh), coal.Transform3s()
    hull = convex_hull(mesh.vertices)
    rng = np.random.default_rng(7)
    low, high = mesh.bounds[0] - 0.1, mesh.bounds[1] + 0.1
    decided = within_hull = 0
    for _ in range(300):
        ball = coal.Sphere(float(rng.uniform(0.005, 0.04)))
        placed = coal.Transform3s(np.eye(3), rng.uniform(low, high))
        margin_m = float(rng.choice([0.0, 0.005, 0.02]))
        apart_m = pieces_apart(pieces, at, (ball,), placed, margin_m)
        exact_m = _distance(bvh, ball, placed)
        if _distance(hull, ball, placed) < margin_m:
            within_hull += 1
        if apart_m is not None:
            decided += 1
            assert margin_m + COLLIDE_MARGIN_AT_LEAST_M <= apart_m <= exact_m + 1e-9
    # the hull comes within the margin where the pieces often keep it
    assert within_hull > 50 and decided > 150


def test_two_meshes_pieces_distance_is_at_most_theirs_and_keeps_the_margin() -> None:
    mesh = forearm()
    pieces, bvh = convex_pieces(np.asarray(mesh.triangles)), bvh_of(mesh)
    hull = convex_hull(mesh.vertices)
    rng = np.random.default_rng(11)
    decided = 0
    for _ in range(150):
        rotation = pin.exp3(rng.normal(size=3))
        other = pin.SE3(rotation, rng.uniform(-0.25, 0.25, 3))
        margin_m = float(rng.choice([0.0, 0.005, 0.02]))
        first = Side(pieces, coal.Transform3s(), hull, pin.SE3.Identity())
        second = Side(pieces, coal.Transform3s(other), hull, other)
        apart_m = sides_apart(first, second, margin_m)
        if apart_m is not None:
            decided += 1
            exact_m = coal.distance(
                bvh,
                coal.Transform3s(),
                bvh,
                coal.Transform3s(other),
                coal.DistanceRequest(),
                coal.DistanceResult(),
            )
            assert margin_m + COLLIDE_MARGIN_AT_LEAST_M <= apart_m <= exact_m + 1e-9
    assert decided > 30


def test_a_side_without_shapes_proves_nothing() -> None:
    ball, at = coal.Sphere(0.01), coal.Transform3s()
    far = coal.Transform3s(np.eye(3), np.array([5.0, 0.0, 0.0]))
    assert pieces_apart((), at, (ball,), far, 0.0) is None
    assert pieces_apart((ball,), at, (ball,), far, 0.0) == pytest.approx(4.98)


def test_a_flat_mesh_has_no_pieces() -> None:
    corners = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    square = corners[[[0, 1, 2], [0, 2, 3]]]
    assert mesh_pieces(square) == ()


def test_the_pieces_are_read_from_disk_once_made(monkeypatch: pytest.MonkeyPatch) -> None:
    triangles = np.asarray(l_shape().triangles)
    made = mesh_pieces(triangles)

    def refuse(*_: object) -> None:
        raise AssertionError("cut again")

    monkeypatch.setattr(mesh_pieces_module, "_cut", refuse)
    again = mesh_pieces(triangles)
    assert len(again) == len(made) and all(np.array_equal(a, b) for a, b in zip(again, made, strict=True))


def _distance(
    shape: coal.CollisionGeometry, other: coal.CollisionGeometry, placed: coal.Transform3s
) -> float:
    """The distance [m] (coal's) of ``shape`` at the origin and ``other`` at ``placed``."""
    result = coal.DistanceResult()
    return float(coal.distance(shape, coal.Transform3s(), other, placed, coal.DistanceRequest(), result))
