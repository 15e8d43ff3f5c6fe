"""The exact meshes kept beside their hulls: excess against geometry, containment against trimesh."""

from __future__ import annotations

import math
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

from cpr_kin.common.disk_cache import cache_folder
from cpr_kin.shapes.exact_meshes import ExactMesh, MeshSource, exact_meshes, hull_excess
from cpr_kin.shapes.mesh_geometry import hull_planes


def bvh_of(mesh: trimesh.Trimesh) -> coal.BVHModelOBBRSS:
    """coal's triangle model of ``mesh``."""
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(len(mesh.faces), len(mesh.vertices))
    bvh.addVertices(np.asarray(mesh.vertices, dtype=float))
    bvh.addTriangles(np.asarray(mesh.faces, dtype=np.int64))
    bvh.endModel()
    return bvh


def exact_mesh_of(mesh: trimesh.Trimesh) -> ExactMesh:
    """``mesh`` as an exact mesh of geometry 0, in its own frame (excess not measured)."""
    triangles = np.asarray(mesh.triangles)
    corners = np.unique(triangles.reshape(-1, 3), axis=0)
    return ExactMesh(
        0, bvh_of(mesh), pin.SE3.Identity(), math.inf, triangles, None, hull_planes(triangles), corners
    )


def l_shape() -> trimesh.Trimesh:
    """Two boxes, 1 x 0.5 and 0.5 x 0.5 (x, y) and 0.1 high, in an L: its hull fills the notch."""
    long = trimesh.creation.box(extents=(1.0, 0.5, 0.1))
    long.apply_translation((0.5, 0.25, 0.05))
    short = trimesh.creation.box(extents=(0.5, 0.5, 0.1))
    short.apply_translation((0.25, 0.75, 0.05))
    joined: trimesh.Trimesh = trimesh.util.concatenate([long, short])  # type: ignore[assignment]
    return joined


def source_of(mesh: trimesh.Trimesh, tmp_path: Path, name: str) -> MeshSource:
    path = tmp_path / f"{name}.stl"
    mesh.export(path)
    return MeshSource(0, bvh_of(mesh), pin.SE3.Identity(), str(path), (1.0, 1.0, 1.0))


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))


def test_an_ls_hull_exceeds_it_by_the_notchs_depth(tmp_path: Path) -> None:
    # the hull's face across the notch, x + y = 1.5, is farthest from the L at its middle
    # (0.75, 0.75): 0.25 m from both inner faces; the sampled largest is below that, by little
    found = hull_excess(source_of(l_shape(), tmp_path, "l"), samples=4000)
    assert 0.23 < found["excess_m"] <= 0.25 + 1e-9
    meshes = exact_meshes([source_of(l_shape(), tmp_path, "l")])
    assert set(meshes) == {0} and 0.23 < meshes[0].excess_m <= 0.25 + 1e-9  # the default sample count
    assert meshes[0].piece_points is not None and len(meshes[0].piece_points) == 2  # two boxes


def test_a_convex_mesh_is_its_own_hull_and_is_not_kept(tmp_path: Path) -> None:
    box = trimesh.creation.box(extents=(0.3, 0.2, 0.1))
    assert hull_excess(source_of(box, tmp_path, "box"))["excess_m"] < 1e-9
    assert exact_meshes([source_of(box, tmp_path, "box")]) == {}


def test_the_excess_is_computed_once_per_file_and_kept_on_disk(tmp_path: Path) -> None:
    source = source_of(l_shape(), tmp_path, "l")
    first = hull_excess(source, samples=500)
    kept = list((cache_folder() / "hull-excess").glob("*.json"))
    assert len(kept) == 1
    kept[0].write_text('{"excess_m": 0.125, "spacing_m": 0.01}')  # what is kept is what is read
    assert hull_excess(source, samples=500)["excess_m"] == 0.125
    kept[0].write_text("{cut sho")  # a broken entry is computed again
    assert hull_excess(source, samples=500) == first
    doubled = l_shape()
    doubled.vertices *= 2.0
    other = source_of(doubled, tmp_path, "l2")  # another file: its own entry
    assert hull_excess(other, samples=500)["excess_m"] == pytest.approx(2 * first["excess_m"], rel=0.1)


def test_the_triangles_are_the_meshs_from_the_first_load_and_from_the_disk(tmp_path: Path) -> None:
    mesh = l_shape()
    corners = np.sort(np.asarray(mesh.triangles).reshape(len(mesh.faces), -1), axis=0)  # trimesh's
    first = exact_meshes([source_of(mesh, tmp_path, "l")])[0]
    kept = list((cache_folder() / "mesh-faces").glob("*.npy"))
    assert len(kept) == 1
    again = exact_meshes([source_of(mesh, tmp_path, "l")])[0]  # read from the disk
    for found in (first, again):
        assert np.array_equal(np.sort(found.triangles.reshape(len(mesh.faces), -1), axis=0), corners)
    kept[0].write_bytes(b"\x93NUMPY cut sho")  # a broken entry is computed again
    assert np.array_equal(exact_meshes([source_of(mesh, tmp_path, "l")])[0].triangles, first.triangles)
    assert first.piece_points is not None and again.piece_points is not None
    assert np.array_equal(first.piece_points, again.piece_points)
    assert np.allclose(first.hull_planes, again.hull_planes)


@pytest.mark.parametrize("flipped", [False, True])
def test_holds_agrees_with_trimeshs_signed_distance_on_a_torus_whichever_way_it_faces(flipped: bool) -> None:
    torus = trimesh.creation.torus(major_radius=0.2, minor_radius=0.05, major_sections=48, minor_sections=24)
    points = np.random.default_rng(4).uniform(-0.3, 0.3, (3000, 3)) * (1.0, 1.0, 0.3)
    signed = trimesh.proximity.signed_distance(torus, points)  # type: ignore[no-untyped-call]
    expected = signed > 0.0  # trimesh, its faces outward: positive inside, by the closest point's side
    if flipped:
        torus.invert()
    mesh = exact_mesh_of(torus)
    found = mesh.holds(points)
    assert 100 < expected.sum() < 2900
    near_surface = np.abs(signed) < 1e-3  # within a hair of the faceted surface either may say either
    np.testing.assert_array_equal(found[~near_surface], expected[~near_surface])
    assert not mesh.holds(np.zeros((1, 3)))[0]  # the hole is outside


def rows_sorted(array: np.ndarray) -> np.ndarray:
    """``array``'s rows in lexicographic order."""
    return array[np.lexsort(array.T[::-1])]


@pytest.mark.parametrize("seed", range(3))
def test_the_hull_planes_are_scipys_qhull_facets(seed: int) -> None:
    """coal's Qhull gives the facets SciPy's does (the same options), each holding every point."""
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(seed)
    torus = trimesh.creation.torus(major_radius=0.2, minor_radius=0.05, major_sections=24, minor_sections=12)
    for points in (np.asarray(torus.vertices), rng.normal(size=(500, 3)) * (0.3, 0.1, 0.05)):
        planes = hull_planes(points)
        expected = ConvexHull(points, qhull_options="Qt").equations
        assert planes.shape == expected.shape
        np.testing.assert_array_equal(rows_sorted(planes), rows_sorted(expected))  # the same facets
        np.testing.assert_allclose(np.linalg.norm(planes[:, :3], axis=1), 1.0)
        assert np.all(points @ planes[:, :3].T + planes[:, 3] <= 1e-12)  # outward normals


def test_a_flat_set_has_no_hull_planes_and_a_flat_mesh_holds_nothing() -> None:
    plate = trimesh.creation.box(extents=(0.2, 0.1, 0.0))  # coal's Qhull crashed on it
    planes = hull_planes(np.asarray(plate.vertices))
    assert planes.shape == (0, 4)
    mesh = exact_mesh_of(plate)  # its hull planes: none, as above
    assert mesh.hull_planes.shape == (0, 4)
    points = np.random.default_rng(5).uniform(-0.15, 0.15, (500, 3)) * (1.0, 1.0, 0.1)
    assert not mesh.holds(points).any()  # a surface of no volume has no inside


def test_holds_any_is_holds_of_the_moved_points_any() -> None:
    torus = trimesh.creation.torus(major_radius=0.2, minor_radius=0.05, major_sections=24, minor_sections=12)
    mesh = exact_mesh_of(torus)
    rng = np.random.default_rng(7)
    answers = []
    for _ in range(200):  # a few points in another frame, placed at random about the torus
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.25, 0.25, 3) * (1.0, 1.0, 0.2))
        points = rng.uniform(-0.05, 0.05, (int(rng.integers(1, 4)), 3))
        moved = points @ placement.rotation.T + placement.translation
        answer = mesh.holds_any(points, placement.rotation, placement.translation)
        assert answer == bool(mesh.holds(moved).any())
        answers.append(answer)
    assert 20 < sum(answers) < 180  # both answers met
    assert not mesh.holds_any(np.zeros((0, 3)), np.eye(3), np.zeros(3))
