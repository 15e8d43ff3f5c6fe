"""An exact mesh's triangles, pieces and hull planes: right, kept on disk, made anew where damaged."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cpr_kin.model.packages import example_robot_data_share
from cpr_kin.shapes import mesh_topology as topology
from cpr_kin.shapes.mesh_geometry import hull_planes
from cpr_kin.shapes.mesh_topology import MAX_PIECES, mesh_topology
from tests.test_exact_meshes import bvh_of


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def boxes(count: int) -> trimesh.Trimesh:
    """``count`` unit boxes 2 m apart along x, one mesh."""
    parts = [trimesh.creation.box(extents=(1.0, 1.0, 1.0)) for _ in range(count)]
    for k, part in enumerate(parts):
        part.apply_translation((2.0 * k, 0.0, 0.0))
    joined = trimesh.util.concatenate(parts)
    assert isinstance(joined, trimesh.Trimesh)
    return joined


@pytest.mark.parametrize("count", [1, 3])
def test_a_point_of_each_piece_as_trimesh_splits_them(count: int) -> None:
    mesh = boxes(count)
    made = mesh_topology(bvh_of(mesh), b"boxes")
    assert made.piece_points is not None and len(made.piece_points) == len(mesh.split(only_watertight=False))
    assert sorted(np.round(made.piece_points[:, 0] / 2.0)) == list(range(count))  # one in each box
    np.testing.assert_array_equal(made.triangles, np.asarray(mesh.vertices)[np.asarray(mesh.faces)])
    np.testing.assert_array_equal(made.corners, np.asarray(mesh.vertices))
    np.testing.assert_array_equal(made.hull_planes, hull_planes(made.corners))


def test_more_pieces_than_the_most_have_no_points() -> None:
    made = mesh_topology(bvh_of(boxes(MAX_PIECES + 1)), b"many")
    assert made.piece_points is None


def test_what_is_kept_is_read_and_not_made_again(monkeypatch: pytest.MonkeyPatch) -> None:
    mesh = boxes(2)
    first = mesh_topology(bvh_of(mesh), b"two")
    monkeypatch.setattr(topology, "_first_of_each_piece", lambda *_: pytest.fail("made again"))
    monkeypatch.setattr(topology, "hull_planes", lambda *_: pytest.fail("made again"))
    again = mesh_topology(bvh_of(mesh), b"two")
    assert first.piece_points is not None and again.piece_points is not None
    np.testing.assert_array_equal(again.piece_points, first.piece_points)
    np.testing.assert_array_equal(again.hull_planes, first.hull_planes)
    np.testing.assert_array_equal(again.triangles, first.triangles)


@pytest.mark.parametrize(
    ("kind", "damaged"),
    [
        ("mesh-components", np.array([10_000], dtype=np.int64)),  # no such vertex
        ("mesh-components", np.array([0.5])),  # not an index
        ("hull-planes", np.full((6, 4), np.nan)),
        ("hull-planes", np.ones((6, 3))),
        ("mesh-faces", np.zeros((3, 3), dtype=np.int64)),  # fewer triangles than the mesh's
    ],
)
def test_a_kept_array_that_does_not_fit_the_mesh_is_made_again(
    own_cache: Path, kind: str, damaged: np.ndarray
) -> None:
    mesh = boxes(2)
    first = mesh_topology(bvh_of(mesh), b"two")
    (kept,) = (own_cache / kind).glob("*.npy")
    np.save(kept, damaged)
    again = mesh_topology(bvh_of(mesh), b"two")
    assert again.piece_points is not None and first.piece_points is not None
    np.testing.assert_array_equal(again.piece_points, first.piece_points)
    np.testing.assert_array_equal(again.hull_planes, first.hull_planes)
    np.testing.assert_array_equal(again.triangles, first.triangles)


@pytest.mark.slow
def test_a_new_process_loading_a_robot_from_its_kept_meshes_imports_no_scipy_graph(own_cache: Path) -> None:
    share = example_robot_data_share()
    assert share is not None, "example-robot-data is part of the robots extra, which make installs"
    urdf = share / "example-robot-data" / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"
    load = f"import sys, cpr_kin as ck; assert ck.load_robot({str(urdf)!r}).exact_meshes; "
    load += "print('scipy.sparse' in sys.modules)"
    said = [
        subprocess.run([sys.executable, "-c", load], capture_output=True, text=True, check=True).stdout
        for _ in range(2)
    ]
    assert said == ["True\n", "False\n"]  # the first made the pieces (SciPy's graph); the second read them
