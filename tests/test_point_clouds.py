"""Point clouds as obstacles: the files read, the voxels that hold the points, coal's distance, the CLI."""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml

import cpr_kin as ck
from cpr_kin.shapes.point_clouds import MAX_POINTS, read_points, voxel_blocks, voxel_centres, voxel_geometry
from planning.cli import main
from planning.io.scene_file import parse_scene, scene_document

RNG = np.random.default_rng(7)
POINTS = np.round(RNG.uniform(-0.3, 0.3, (500, 3)), 6)


def write_pcd(path: Path, points: np.ndarray, binary: bool) -> None:
    header = (
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\n"
        f"TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH {len(points)}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
        f"POINTS {len(points)}\nDATA {'binary' if binary else 'ascii'}\n"
    )
    with_intensity = np.column_stack([points, np.ones(len(points))]).astype(np.float32)
    if binary:
        path.write_bytes(header.encode() + b"".join(struct.pack("<4f", *row) for row in with_intensity))
    else:
        path.write_text(
            header + "\n".join(" ".join(f"{v:.6f}" for v in row) for row in with_intensity) + "\n"
        )


def test_every_format_reads_the_same_points(tmp_path: Path) -> None:
    np.save(tmp_path / "c.npy", POINTS)
    np.savetxt(tmp_path / "c.xyz", np.column_stack([POINTS, np.zeros(len(POINTS))]), fmt="%.6f")
    trimesh.PointCloud(POINTS).export(tmp_path / "c.ply")  # type: ignore[no-untyped-call]
    write_pcd(tmp_path / "ascii.pcd", POINTS, binary=False)
    write_pcd(tmp_path / "binary.pcd", POINTS, binary=True)
    for name in ("c.npy", "c.xyz", "c.ply", "ascii.pcd", "binary.pcd"):
        np.testing.assert_allclose(read_points(tmp_path / name), POINTS, atol=1e-6, err_msg=name)


def test_the_voxels_contain_every_point_and_the_blocks_partition_them() -> None:
    resolution = 0.02
    centres = voxel_centres(POINTS, resolution)
    # each point lies in a cube of side `resolution` about some centre (an identity of the grid)
    nearest = np.abs(POINTS[:, None, :] - centres[None]).max(axis=2).min(axis=1)
    assert np.all(nearest <= resolution / 2 + 1e-12)
    assert len(np.unique(centres, axis=0)) == len(centres) <= len(POINTS)
    blocks = voxel_blocks(centres, 0.25)
    assert sum(len(b) for b in blocks) == len(centres)
    assert len(np.unique(np.vstack(blocks), axis=0)) == len(centres)
    for block in blocks:  # every block within one cell of the block grid
        cells = np.floor(block / 0.25)
        assert np.all(cells == cells[0])


def test_coals_distance_is_the_distance_to_the_union_of_cubes() -> None:
    # an independent oracle: a sphere's distance to the union is the least point-to-box distance
    import coal

    resolution = 0.02
    centres = voxel_centres(POINTS, resolution)
    tree = voxel_geometry(centres, resolution)
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    for centre in RNG.uniform(-0.6, 0.6, (20, 3)):
        gaps = np.maximum(np.abs(centres - centre) - resolution / 2, 0.0)
        expected = np.sqrt((gaps**2).sum(axis=1)).min() - 0.05
        if expected <= 0.0:
            continue
        placed = coal.Transform3s()
        placed.setTranslation(centre)
        result.clear()
        distance = coal.distance(coal.Sphere(0.05), placed, tree, coal.Transform3s(), request, result)
        assert distance == pytest.approx(expected, abs=1e-6)


def test_the_closest_points_are_on_the_robot_and_the_cloud() -> None:
    robot = ck.load_cpr()
    q = np.array([0.3, 0.4, 0.3, 0.0, 0.0])
    tcp = ck.frame_positions(robot, q)
    slab = np.array(
        [[x, y, tcp[2] - 0.3] for x in np.arange(-0.1, 0.1, 0.01) for y in np.arange(-0.1, 0.1, 0.01)]
    )
    cloud = ck.Obstacle(
        shape="voxels",
        points=voxel_centres(slab + tcp * [1, 1, 0], 0.01),
        resolution=0.01,
        xyz=np.zeros(3),
        name="slab",
    )
    closest = ck.CollisionWorld(robot, [cloud]).clearance(q).closest
    assert closest is not None and closest.obstacle == "slab"
    assert closest.point_on_obstacle[2] < closest.point_on_robot[2]  # the slab is below the tool
    assert closest.point_on_robot[2] - closest.point_on_obstacle[2] == pytest.approx(
        closest.distance_m, abs=1e-6
    )


SCENE = {
    "start": {"q": [0.0, 0.1, 0.1, 0.0, 0.0]},
    "goal": {"q": [1.5, 0.5, 0.4, 1.0, 0.5]},
    "safety_margin": 0.03,
}


def test_a_cloud_scene_plans_certified_and_reads_back_as_the_same_voxels(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    post = trimesh.creation.box(extents=(0.1, 0.1, 0.6))
    post.apply_translation([0.45, 0.45, 0.3])
    np.save(tmp_path / "post.npy", trimesh.sample.sample_surface(post, 20_000, seed=1)[0])
    cloud = {"name": "post", "shape": "point_cloud", "file": "post.npy", "resolution": 0.01}
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({**SCENE, "obstacles": [cloud]}))
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert main(["check", str(scene), str(tmp_path / "out" / "trajectory.json")]) == 0
    parsed = parse_scene(yaml.safe_load(scene.read_text()), base=tmp_path)
    assert len(parsed.obstacles) > 1 and all(o.shape == "voxels" for o in parsed.obstacles)
    again = parse_scene(scene_document(parsed))  # the voxel centres, block by block
    assert again.obstacles == parsed.obstacles


@pytest.mark.parametrize(
    ("cloud", "message"),
    [
        ({"points": []}, "obstacles[0].points: 0 items; needs at least 1"),
        (
            {"points": [[0.1, 0.2, float("nan")]]},
            "obstacles[0].points[0][2] = nan: Input should be a finite number",
        ),
        (
            {"points": [[0.1, 0.2, 0.3]], "resolution": 0.0},
            "obstacles[0].resolution = 0.0: Input should be greater",
        ),
        ({"points": [[0.1, 0.2, 0.3]], "resolution": -1.0}, "obstacles[0].resolution = -1.0"),
        (
            {"file": "big.npy"},
            f"holds an array of shape (100000000, 3); expected (N, 3), N at most {MAX_POINTS}",
        ),
        ({"file": "none.npy"}, "none.npy' does not exist"),
        (
            {"file": "a.las"},
            "a point cloud is one of ['.npy', '.xyz', '.txt', '.ply', '.pcd'] (or an OctoMap file",
        ),
        (
            {"file": "c.npy", "points": [[0, 0, 0]]},
            "give exactly one of 'file' (a point-cloud or octree file) or 'points'",
        ),
    ],
)
def test_a_bad_cloud_is_refused_fast_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], cloud: dict[str, object], message: str
) -> None:
    with (tmp_path / "big.npy").open("wb") as stream:  # a header of 10^8 points, the data left out
        np.lib.format.write_array_header_1_0(
            stream, {"descr": "<f8", "fortran_order": False, "shape": (10**8, 3)}
        )
    (tmp_path / "a.las").write_bytes(b"LASF")
    entry = {"name": "camera", "shape": "point_cloud", "resolution": 0.01, **cloud}
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({**SCENE, "obstacles": [entry]}))
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1, error
    assert not (tmp_path / "out").exists()
