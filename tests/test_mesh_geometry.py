"""Whether points span a volume: the precondition of every convex hull built with Qhull."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull, QhullError
from scipy.spatial.transform import Rotation

from cpr_kin.shapes.mesh_geometry import spans_volume


@pytest.mark.parametrize("seed", range(4))
def test_a_set_spans_a_volume_exactly_where_scipys_qhull_builds_a_hull_of_volume(seed: int) -> None:
    rng = np.random.default_rng(seed)
    turn = Rotation.random(random_state=seed).as_matrix()
    solid = rng.normal(size=(50, 3)) * (0.3, 0.1, 0.05)
    flat = np.c_[rng.normal(size=(50, 2)), np.zeros(50)]
    line = np.outer(rng.normal(size=20), [1.0, 2.0, -0.5])
    for points, expected in ((solid, True), (flat, False), (line, False), (solid[:3], False)):
        moved = points @ turn.T + rng.normal(size=3)  # placed anywhere, turned any way
        assert spans_volume(moved) is expected
        if expected:
            assert ConvexHull(moved).volume > 0.0
        else:
            with pytest.raises((QhullError, ValueError)):
                ConvexHull(moved)


def test_a_thin_solid_spans_a_volume_and_a_flat_one_does_not() -> None:
    assert spans_volume(trimesh.creation.box(extents=(0.2, 0.1, 1e-4)).vertices)
    assert not spans_volume(trimesh.creation.box(extents=(0.2, 0.1, 0.0)).vertices)


@pytest.mark.slow
def test_coals_qhull_builds_every_thin_box_spans_volume_accepts() -> None:
    """Boxes from 1e-8 to 1e-3 m thin, about the origin and 10 and 100 m from it: where ``spans_volume``
    accepts one, coal builds its hull (in a child process: coal crashes, it raises nothing)."""
    import subprocess
    import sys

    program = """
import sys
import coal, numpy as np, trimesh
from cpr_kin.shapes.mesh_geometry import spans_volume
for thickness in (1e-8, 3e-8, 1e-7, 3e-7, 1e-6, 1e-5, 1e-4, 1e-3):
    for offset in (0.0, 10.0, 100.0):
        box = trimesh.creation.box(extents=(0.2, 0.1, thickness))
        box.apply_translation([offset, 0.0, 0.0])
        vertices, faces = np.asarray(box.vertices, float), np.asarray(box.faces, np.int64)
        if not spans_volume(vertices):
            continue
        mesh = coal.BVHModelOBBRSS()
        mesh.beginModel(len(faces), len(vertices))
        mesh.addVertices(vertices)
        mesh.addTriangles(faces)
        mesh.endModel()
        mesh.buildConvexHull(True, "Qt")
        print(thickness, offset, mesh.convex.num_points, flush=True)
"""
    run = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, timeout=120, check=False
    )
    assert run.returncode == 0, run.stderr[-2000:]
    built = [line.split() for line in run.stdout.splitlines()]
    assert len(built) >= 8 and all(points == "8" for *_, points in built)  # a box's eight corners
    assert ["1e-08", "0.0", "8"] not in built  # the thinnest is flat, wherever it lies
