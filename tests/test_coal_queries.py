"""How coal is asked: a placement as coal's transform (the same rotation, translation and action)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from cpr_kin.shapes.coal_queries import as_transform


@pytest.mark.parametrize("seed", [0, 1])
def test_as_transform_places_points_as_the_pinocchio_placement_does(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(50):
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-2.0, 2.0, 3))
        transform = as_transform(placement)
        point = rng.uniform(-1.0, 1.0, 3)
        assert np.array_equal(transform.getRotation(), placement.rotation)
        assert np.array_equal(transform.getTranslation(), placement.translation)
        np.testing.assert_allclose(transform.transform(point), placement.act(point), rtol=0, atol=1e-15)
