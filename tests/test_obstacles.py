from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
import trimesh

import cpr_kin as ck


@pytest.mark.parametrize(
    ("make", "pattern"),
    [
        (
            lambda: ck.Obstacle.box((0.3, -0.1, 0.3), (0, 0, 0), name="crate"),
            r"'crate' size = \[0\.3, -0\.1, 0\.3\] must be finite numbers in \[0\.0001, 100\] m",
        ),
        (lambda: ck.Obstacle.box((0.3, 0.3), (0, 0, 0)), r"size = \[0\.3, 0\.3\] must have 3 values"),
        (
            lambda: ck.Obstacle.sphere(0.1, (0, math.nan, 0), name="ball"),
            r"'ball' xyz = \[0\.0, nan, 0\.0\] must be finite numbers in \[-100, 100\] m",
        ),
        (
            lambda: ck.Obstacle.sphere(-0.1, (0, 0, 0), name="ball"),
            r"'ball' radius = -0\.1 must be a number in \[0\.0001, 100\] m",
        ),
        (
            lambda: ck.Obstacle.cylinder(0.1, 0.0, (0, 0, 0), name="pipe"),
            r"'pipe' length = 0 must be a number in \[0\.0001, 100\] m",
        ),
        (
            lambda: ck.Obstacle.capsule(0.1, 0.2, (0, 0, 0), rpy=(0, math.inf, 0)),
            r"rpy = \[0\.0, inf, 0\.0\] must be finite numbers in \[-100, 100\] rad",
        ),
        (
            lambda: ck.Obstacle.sphere(0.1, (1e200, 0, 0), name="far"),
            r"'far' xyz = \[1e\+200, 0\.0, 0\.0\] must be finite numbers in \[-100, 100\] m",
        ),
        (
            lambda: ck.Obstacle.sphere(True, (0, 0, 0), name="flag"),
            r"'flag' radius = True must be a number in \[0\.0001, 100\] m",
        ),
        (
            lambda: ck.Obstacle.box((0.1, 0.1, 0.1), (0, 0, 0), name="x" * 101),
            r"obstacle name 'xxx.*\.\.\. must be 1 to 100 characters",
        ),
        (
            lambda: ck.Obstacle(shape="cone", xyz=np.zeros(3)),  # type: ignore[arg-type]
            r"unknown shape 'cone'; allowed: \['box', 'sphere', 'cylinder', 'capsule', 'mesh', 'voxels'\]",
        ),
        (
            lambda: ck.Obstacle.from_mesh("/no/such/file.stl", (0, 0, 0)),
            r"mesh file '/no/such/file\.stl' does not exist",
        ),
        (
            lambda: ck.Obstacle.from_mesh("/dev/zero", (0, 0, 0)),
            r"mesh file '/dev/zero' is not a regular file",
        ),
        (
            lambda: ck.Obstacle.from_mesh("/tmp", (0, 0, 0)),
            r"mesh file '/tmp' is not a regular file",
        ),
    ],
)
def test_invalid_obstacles(make: object, pattern: str) -> None:
    with pytest.raises(ck.ObstacleError, match=pattern):
        make()  # type: ignore[operator]


def test_unreadable_mesh(tmp_path: Path) -> None:
    path = tmp_path / "junk.stl"
    path.write_text("this is not a mesh")
    with pytest.raises(ck.ObstacleError, match=re.escape("junk.stl")):
        ck.Obstacle.from_mesh(path, (0, 0, 0)).geometry()


@pytest.mark.parametrize(
    "vertices",
    [
        [[0, 0, 0], [1, 0, 0], [0, 1, 0]],  # one triangle: flat
        [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]],  # a flat quad
        [[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]],  # a line
    ],
)
def test_a_degenerate_mesh_has_no_convex_hull_but_its_surface_works(
    tmp_path: Path, vertices: list[list[float]]
) -> None:
    path = tmp_path / "flat.stl"
    faces = [[0, 1, 2]] + ([[1, 3, 2]] if len(vertices) == 4 else [])
    trimesh.Trimesh(vertices=vertices, faces=faces, process=False).export(path)
    with pytest.raises(ck.ObstacleError, match=r"is flat \(its vertices span no volume\).*convex: false"):
        ck.Obstacle.from_mesh(path, (0, 0, 0)).geometry()
    ck.Obstacle.from_mesh(path, (0, 0, 0), convex=False).geometry()  # a surface is fine


def test_placement_from_rpy() -> None:
    obstacle = ck.Obstacle.box((1, 2, 3), (0.1, 0.2, 0.3), rpy=(0.0, 0.0, math.pi / 2))
    placement = obstacle.placement
    np.testing.assert_allclose(placement.translation, [0.1, 0.2, 0.3])
    np.testing.assert_allclose(placement.rotation @ [1, 0, 0], [0, 1, 0], atol=1e-15)


@pytest.mark.parametrize("convex", [True, False])
def test_mesh_box_matches_primitive_box(
    robot: ck.Robot, rng: np.random.Generator, tmp_path: Path, convex: bool
) -> None:
    path = tmp_path / "crate.stl"
    trimesh.creation.box(extents=(0.15, 0.15, 0.15)).export(path)
    kwargs = {"xyz": (0.0, 0.6, 0.15), "rpy": (0.1, 0.0, 0.3)}
    primitive = ck.CollisionWorld(robot, [ck.Obstacle.box((0.3, 0.3, 0.3), name="crate", **kwargs)])
    mesh = ck.CollisionWorld(
        robot, [ck.Obstacle.from_mesh(path, scale=2.0, convex=convex, name="crate", **kwargs)]
    )
    configurations = rng.uniform(robot.limits.lower, robot.limits.upper, (200, robot.nq))
    a = primitive.clearance_batch(configurations).clearance_m
    b = mesh.clearance_batch(configurations).clearance_m
    separated = a > 1e-3
    assert separated.sum() > 300
    # coal stops GJK at a tolerance of about 1e-6 m on triangle meshes
    np.testing.assert_allclose(b[separated], a[separated], atol=1e-5)
