"""A PlanningScene's octomap imported: the tree's voxels placed as MoveIt places them, its file, refusals."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
import octomap
import pytest
from scipy.spatial.transform import Rotation

from planning.cli import main
from planning.io.scene_file import load_scene
from tests.test_moveit_import import REQUEST, SCENE, write
from tests.test_octree_files import keys_of, occupied_keys

RESOLUTION_M = 0.02
ORIGIN = {"position": [0.4, -0.1, 0.2], "orientation": [0.0, 0.0, 0.3826834, 0.9238795]}


def a_tree() -> octomap.OcTree:
    tree = octomap.OcTree(RESOLUTION_M)
    rng = np.random.default_rng(11)
    for point in rng.uniform([0.0, 0.0, 0.0], [0.1, 0.2, 0.3], (3000, 3)):
        tree.updateNode(point, True)
    for point in rng.uniform(-0.2, 0.2, (500, 3)):
        tree.updateNode(point, False)
    return tree


def with_octomap(tree: octomap.OcTree, binary: bool, frame: str = "panda_link0") -> dict[str, Any]:
    encoded = tree.writeBinary() if binary else tree.write()
    data = encoded.partition(b"data\n")[2]
    scene = copy.deepcopy(SCENE)
    scene["world"]["octomap"] = {
        "header": {"frame_id": frame},
        "origin": ORIGIN,
        "octomap": {
            "binary": binary,
            "id": "OcTree",
            "resolution": RESOLUTION_M,
            "data": np.frombuffer(data, dtype=np.int8).tolist(),  # int8[], as ROS writes it
        },
    }
    return scene


@pytest.mark.parametrize("binary", [True, False])
def test_an_octomap_becomes_the_trees_voxels_at_its_origin(tmp_path: Path, binary: bool) -> None:
    tree = a_tree()
    out = tmp_path / "out" / "shelf.yaml"
    assert (
        main(["import-moveit", *write(tmp_path, with_octomap(tree, binary), REQUEST), "--out", str(out)]) == 0
    )
    written = out.parent / f"shelf_octomap{'.bt' if binary else '.ot'}"
    opened = octomap.OcTree(str(written).encode()) if binary else octomap.OcTree.read(str(written).encode())
    assert opened.size() == tree.size()  # OctoMap opens the file
    scene = load_scene(out)
    voxels = [o for o in scene.obstacles if o.name.startswith("octomap")]
    centres = np.vstack([np.asarray(v.points) for v in voxels])
    np.testing.assert_array_equal(keys_of(centres, RESOLUTION_M), occupied_keys(tree))  # pruned ones too
    origin = np.eye(4)
    origin[:3, :3] = Rotation.from_quat(ORIGIN["orientation"]).as_matrix()
    origin[:3, 3] = ORIGIN["position"]
    for block in voxels:  # the cloud's frame at the origin, in the base frame (panda_link0)
        np.testing.assert_allclose(block.xyz, origin[:3, 3], atol=1e-9)
        np.testing.assert_allclose(
            Rotation.from_euler("xyz", block.rpy).as_matrix(), origin[:3, :3], atol=1e-6
        )
        assert block.resolution == pytest.approx(RESOLUTION_M)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda m: m["octomap"].update(data=m["octomap"]["data"][:-5]), "the data ends inside the tree"),
        (lambda m: m["octomap"].update(id="ColorOcTree"), "is a 'ColorOcTree'; only OctoMap's 'OcTree'"),
        (lambda m: m["octomap"].update(resolution=0.0), "octomap.resolution = 0 m; a scene's voxels are"),
        (lambda m: m["header"].update(frame_id="panda_hand"), "frame 'panda_hand' is a link that joint"),
        (lambda m: m["octomap"].update(data=[300]), "data[0] = 300"),
    ],
)
def test_a_broken_octomap_is_refused_naming_the_field_and_nothing_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], change: Any, message: str
) -> None:
    scene = with_octomap(a_tree(), binary=True)
    change(scene["world"]["octomap"])
    out = tmp_path / "out.yaml"
    assert main(["import-moveit", *write(tmp_path, scene, REQUEST), "--out", str(out)]) == 2
    error = capsys.readouterr().err
    assert "octomap" in error and message in error and len(error.strip().splitlines()) == 1, error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["request.yaml", "scene.yaml"]
