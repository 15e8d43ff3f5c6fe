"""How coal is asked: a Pinocchio placement as its transform, and the least margin of its collision test."""

from __future__ import annotations

from typing import Any

import coal
import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

COLLIDE_MARGIN_AT_LEAST_M = 1e-6
"""The least margin [m] coal's collision test is asked with (:func:`collide_margin_m`). At a margin of
0 its GJK, warm-started from the pair's last query, can prove two shapes apart by a lower bound
of 1e-12 m while they are 5 cm deep (coal 3.0.3: two cylinders of the Z1, docs/tuning.md); its
distances are good to 1e-6 m (:data:`cpr_kin.collision.decisive.COAL_RELATIVE_ERROR`), so at
this margin a test answers within that."""


def collide_margin_m(margin_m: float | FloatArray) -> FloatArray:
    """The margin [m] coal's collision test is asked with for ``margin_m`` [m]: at least the floor.

    :data:`COLLIDE_MARGIN_AT_LEAST_M`: a margin below it (0, or a pair's margin less its
    allowance) is asked at it.
    """
    return np.maximum(margin_m, COLLIDE_MARGIN_AT_LEAST_M)


def swept_radius_m(shape: Any) -> float:
    """The radius [m] coal sweeps ``shape`` by (its swept sphere radius; 0 where it has none)."""
    return float(shape.getSweptSphereRadius()) if hasattr(shape, "getSweptSphereRadius") else 0.0


def as_transform(placement: Any) -> Any:
    """The ``coal.Transform3s`` of a Pinocchio placement (``pinocchio.SE3``).

    By the conversion Pinocchio registers with coal, without NumPy copies of its rotation and
    translation between them (the same numbers; a mesh's pair test asks two a query).
    """
    return coal.Transform3s(placement)
