"""OctoMap files as voxels: read as OctoMap reads them (octomap-python, the oracle), refusals, scenes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import octomap
import pytest
import yaml

from cpr_kin.common.errors import ObstacleError
from cpr_kin.shapes.octree_files import MAX_VOXELS, octree_voxels, read_octree
from planning.cli import main
from planning.io.scene_file import parse_scene

RESOLUTION_M = 0.05


def a_tree(seed: int) -> octomap.OcTree:
    """Occupied and free voxels at random, and a solid block whose nodes OctoMap prunes."""
    rng = np.random.default_rng(seed)
    tree = octomap.OcTree(RESOLUTION_M)
    for point in rng.uniform(-1.0, 1.0, (2000, 3)):
        tree.updateNode(point, True)
    for point in rng.uniform(-1.0, 1.0, (2000, 3)):
        tree.updateNode(point, False)
    block = np.arange(0.0, 0.4, RESOLUTION_M) + RESOLUTION_M / 2
    for _ in range(6):  # hit until clamped: the eight children agree and are pruned into one
        for x in block:
            for y in block:
                for z in block:
                    tree.updateNode(np.array([x, y, z]), True)
    return tree


def occupied_keys(tree: octomap.OcTree) -> np.ndarray:
    """OctoMap's own occupied leaves, each pruned one as the voxels it covers, as grid keys."""
    keys, resolution_m = [], tree.getResolution()
    for leaf in tree.begin_leafs():
        if tree.isNodeOccupied(leaf):
            span = round(leaf.getSize() / resolution_m)
            low = np.round(np.asarray(leaf.getCoordinate()) / resolution_m - span / 2).astype(int)
            grid = np.meshgrid(*(np.arange(k, k + span) for k in low), indexing="ij")
            keys.append(np.stack(grid, axis=-1).reshape(-1, 3))
    return np.unique(np.vstack(keys), axis=0)


def keys_of(centres: np.ndarray, resolution_m: float = RESOLUTION_M) -> np.ndarray:
    return np.unique(np.floor(centres / resolution_m).astype(int), axis=0)


@pytest.mark.parametrize("suffix", [".bt", ".ot"])
def test_a_file_reads_as_octomap_reads_it(tmp_path: Path, suffix: str) -> None:
    tree = a_tree(seed=1)
    path = tmp_path / f"room{suffix}"
    assert (tree.writeBinary if suffix == ".bt" else tree.write)(str(path).encode())
    voxels = read_octree(path)
    expected = occupied_keys(tree)
    assert any(leaf.getDepth() < 16 for leaf in tree.begin_leafs())  # pruned nodes are in the file
    assert len(voxels.centres) == len(expected)
    np.testing.assert_array_equal(keys_of(voxels.centres), expected)
    assert voxels.resolution_m == pytest.approx(RESOLUTION_M) and voxels.node_count == tree.size()
    # each centre the middle of its cube: half a side from the grid
    np.testing.assert_allclose(np.mod(voxels.centres / RESOLUTION_M, 1.0), 0.5, atol=1e-9)


def test_an_empty_tree_has_no_voxel(tmp_path: Path) -> None:
    path = tmp_path / "empty.bt"
    assert octomap.OcTree(0.1).writeBinary(str(path).encode())
    assert read_octree(path).centres.shape == (0, 3)


def test_a_broken_or_foreign_tree_is_refused_naming_it(tmp_path: Path) -> None:
    tree = a_tree(seed=2)
    data = tree.writeBinary()
    header, _, body = data.partition(b"data\n")
    cases = {
        "cut.bt": (header + b"data\n" + body[:-7], "the data ends inside the tree"),
        "long.bt": (data + b"\x00\x00", "2 bytes follow the tree's end"),
        "text.bt": (b"hello\n", "starts with 'hello'; an OctoMap file starts with one of"),
        "color.ot": (
            b"# Octomap OcTree file\nid ColorOcTree\nsize 1\nres 0.1\ndata\n",
            "is a 'ColorOcTree'; only OctoMap's 'OcTree' is read",
        ),
        "nores.bt": (b"# Octomap OcTree binary file\nid OcTree\nsize 3\ndata\n", "needs 'res'"),
        "nodata.bt": (b"# Octomap OcTree binary file\nid OcTree\nsize 3\nres 0.1\n", "has no 'data' line"),
    }
    for name, (content, message) in cases.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(ObstacleError, match="octree") as error:
            read_octree(tmp_path / name)
        assert message in str(error.value), name


def test_a_pruned_node_of_too_many_voxels_is_refused_before_they_are_made() -> None:
    # the root's child 0 an occupied leaf: 2**45 voxels
    with pytest.raises(ObstacleError, match=f"35184372088832 occupied voxels; at most {MAX_VOXELS}"):
        octree_voxels(bytes([0b10, 0]), 0.01, binary=True, what="octree 'x'")


def test_a_scene_reads_an_octree_as_the_same_voxels_as_its_points(tmp_path: Path) -> None:
    tree = a_tree(seed=3)
    assert tree.writeBinary(str(tmp_path / "room.bt").encode())
    voxels = read_octree(tmp_path / "room.bt")
    np.save(tmp_path / "room.npy", voxels.centres)
    scenes = [
        parse_scene(
            {
                "start": {"q": [0.0, 0.1, 0.1, 0.0, 0.0]},
                "goal": {"q": [1.5, 0.5, 0.4, 1.0, 0.5]},
                "obstacles": [{"name": "room", "shape": "point_cloud", "xyz": [2.0, 0, 0], **cloud}],
            },
            base=tmp_path,
        )
        for cloud in ({"file": "room.bt"}, {"file": "room.npy", "resolution": RESOLUTION_M})
    ]
    assert scenes[0].obstacles == scenes[1].obstacles


def test_a_resolution_other_than_the_octrees_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert a_tree(seed=4).writeBinary(str(tmp_path / "room.bt").encode())
    cloud = {"name": "room", "shape": "point_cloud", "file": "room.bt", "resolution": 0.02}
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        yaml.safe_dump({"start": {"q": [0.0] * 5}, "goal": {"q": [1.0] * 5}, "obstacles": [cloud]})
    )
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert "resolution = 0.02 m, but the octree 'room.bt' has 0.05 m" in error
    assert len(error.strip().splitlines()) == 1 and not (tmp_path / "out").exists()
