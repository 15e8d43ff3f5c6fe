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
