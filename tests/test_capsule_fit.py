from __future__ import annotations

import itertools
from pathlib import Path

import coal
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from cpr_kin.bounds.capsule_fit import (
    Capsule,
    _fitted,
    capsule_along,
    enclosing_circle,
    fitted_capsule,
    frame_about,
)
from cpr_kin.bounds.pair_bounds import bounding_capsule


def soup(vertices: np.ndarray, faces: np.ndarray) -> coal.BVHModelOBBRSS:
    """A coal triangle mesh."""
    mesh = coal.BVHModelOBBRSS()
    mesh.beginModel(len(faces), len(vertices))
    mesh.addVertices(np.asarray(vertices, dtype=np.float64))
    mesh.addTriangles(np.asarray(faces, dtype=np.int64))
    mesh.endModel()
    return mesh


def hull(vertices: np.ndarray, faces: np.ndarray) -> coal.Convex:
    """Their convex hull, as the robot loader makes of a link's mesh."""
    mesh = soup(vertices, faces)
    mesh.buildConvexHull(True, "Qt")
    return mesh.convex


def brute_force_circle(points: np.ndarray) -> float:
    """The smallest radius over the circles through two or three of ``points`` holding them all."""
    best = np.inf
    for a, b in itertools.combinations(points, 2):
        centre = (a + b) / 2
        radius = np.linalg.norm(a - centre)
        if np.all(np.linalg.norm(points - centre, axis=1) <= radius + 1e-12):
            best = min(best, float(radius))
    for a, b, c in itertools.combinations(points, 3):
        matrix = 2 * np.array([b - a, c - a])
        if abs(np.linalg.det(matrix)) < 1e-12:
            continue
        centre = np.linalg.solve(matrix, [b @ b - a @ a, c @ c - a @ a])
        radius = np.linalg.norm(a - centre)
        if np.all(np.linalg.norm(points - centre, axis=1) <= radius + 1e-12):
            best = min(best, float(radius))
    return float(best)


@pytest.mark.parametrize("seed", range(5))
def test_the_enclosing_circle_is_the_smallest(seed: int) -> None:
    points = np.random.default_rng(seed).normal(size=(12, 2))
    centre, radius = enclosing_circle(points)
    assert np.linalg.norm(points - centre, axis=1).max() <= radius + 1e-15
    assert radius == pytest.approx(brute_force_circle(points), rel=1e-9)


def test_degenerate_point_sets_get_their_circle() -> None:
    line = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 0.0], [2.0, 0.0]])
    assert enclosing_circle(line)[1] == pytest.approx(1.5)
    assert enclosing_circle(np.array([[0.5, -2.0]]))[1] == 0.0
    repeated = np.array([[1.0, 1.0]] * 5 + [[1.0, 3.0]])
    np.testing.assert_allclose(enclosing_circle(repeated)[0], [1.0, 2.0])


def test_a_cylinders_points_give_its_radius_and_length() -> None:
    """Rims of a tilted cylinder, radius 0.05 m and length 0.4 m: the capsule is the cylinder's."""
    rotation = Rotation.from_euler("xyz", [0.3, -0.7, 1.1])
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    rim = np.stack([0.05 * np.cos(angles), 0.05 * np.sin(angles)], axis=1)
    local = np.concatenate([np.column_stack([rim, np.full(64, z)]) for z in (-0.2, 0.0, 0.2)])
    points = rotation.apply(local) + np.array([0.1, 0.2, 0.3])
    capsule = capsule_along(points, rotation.apply([0.0, 0.0, 1.0]))
    assert capsule.radius == pytest.approx(0.05, abs=1e-8)
    assert np.linalg.norm(capsule.ends[1] - capsule.ends[0]) == pytest.approx(0.4, abs=1e-8)
    fitted = fitted_capsule(points)  # finds that axis among the principal ones
    assert fitted.radius == pytest.approx(0.05, abs=1e-8)
    assert fitted.volume == pytest.approx(capsule.volume, rel=1e-6)


@pytest.mark.parametrize("seed", range(4))
def test_the_fitted_capsule_holds_every_point_and_beats_the_box(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(300, 3)) * [0.2, 0.05, 0.03]
    points = Rotation.random(random_state=seed).apply(points)
    fitted = fitted_capsule(points)
    assert np.all(fitted.distances(points) <= fitted.radius)
    shape = hull(points, trimesh.convex.convex_hull(points).faces)
    ends, radius = bounding_capsule(shape)
    assert Capsule(ends, radius).volume <= fitted.volume + 1e-15  # the smaller of box and fit
    assert np.all(Capsule(ends, radius).distances(points) <= radius)


def test_a_meshs_capsule_holds_its_surface_and_is_tighter_than_its_box() -> None:
    """A tilted cylinder mesh, convex and as a triangle soup: points all over its faces lie inside."""
    mesh = trimesh.creation.cylinder(radius=0.04, height=0.3, sections=48)
    tilt = np.eye(4)
    tilt[:3, :3] = Rotation.from_euler("xyz", [0.4, 0.9, -0.2]).as_matrix()
    mesh.apply_transform(tilt)
    surface = mesh.sample(2000, seed=0)
    for shape in (hull(mesh.vertices, mesh.faces), soup(mesh.vertices, mesh.faces)):
        ends, radius = bounding_capsule(shape)
        assert np.all(Capsule(ends, radius).distances(surface) <= radius)
        assert radius < 0.041  # the box's half diagonal across its longest side is far wider
        shape.computeLocalAABB()
        half = (np.asarray(shape.aabb_local.max_) - np.asarray(shape.aabb_local.min_)) / 2
        assert np.linalg.norm(np.delete(half, np.argmax(half))) > 0.06
    swept = hull(mesh.vertices, mesh.faces)  # coal grows a shape by its swept sphere radius
    swept.setSweptSphereRadius(0.01)
    assert bounding_capsule(swept)[1] == pytest.approx(
        bounding_capsule(hull(mesh.vertices, mesh.faces))[1] + 0.01
    )


@pytest.mark.parametrize("axis", [[0.0, 0.0, 2.0], [1.0, 0.0, 0.0], [0.3, -0.4, 0.5]])
def test_the_frame_about_an_axis_is_right_handed_and_orthonormal(axis: list[float]) -> None:
    frame = frame_about(np.array(axis))
    np.testing.assert_allclose(frame.T @ frame, np.eye(3), atol=1e-15)
    assert np.linalg.det(frame) == pytest.approx(1.0)
    np.testing.assert_allclose(frame[:, 2], np.array(axis) / np.linalg.norm(axis))


def test_the_fit_is_memoised_and_refuses_bad_points() -> None:
    points = np.random.default_rng(9).normal(size=(50, 3))
    assert fitted_capsule(points) is fitted_capsule(points.copy())
    for bad in (np.zeros((0, 3)), np.zeros((4, 2)), np.array([[0.0, np.nan, 1.0]])):
        with pytest.raises(ValueError, match="must be"):
            fitted_capsule(bad)


def test_a_meshs_fit_is_kept_on_disk_and_an_edited_one_is_fitted_anew(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path))
    points = Rotation.random(random_state=3).apply(
        np.random.default_rng(3).normal(size=(400, 3)) * [0.2, 0.05, 0.04]
    )
    fitted = fitted_capsule(points)
    (kept,) = (tmp_path / "capsule-fits").glob("*.npy")
    np.testing.assert_array_equal(np.load(kept), np.append(fitted.ends.ravel(), fitted.radius))
    _fitted.cache_clear()  # a new process: read from disk, the same capsule
    read = fitted_capsule(points)
    assert read is not fitted
    np.testing.assert_array_equal(read.ends, fitted.ends)
    assert read.radius == fitted.radius
    np.save(kept, np.append(fitted.ends.ravel(), fitted.radius / 2))  # edited: it no longer holds them
    _fitted.cache_clear()
    again = fitted_capsule(points)
    assert again.radius == fitted.radius and np.all(again.distances(points) <= again.radius)
    small = np.random.default_rng(4).normal(size=(8, 3))  # a primitive's corners: not kept
    fitted_capsule(small)
    assert len(list((tmp_path / "capsule-fits").glob("*.npy"))) == 1
