"""The ranges an obstacle's values must lie in: coordinates, sizes, angles, mesh files, names."""

from __future__ import annotations

MAX_COORDINATE_M = 100.0
"""Largest |coordinate| of an obstacle's centre [m]: a hundred times an arm's reach (about a metre);
far out the distance arithmetic loses its meaning (at 1e200 m it overflows)."""
SIZE_RANGE_M = (1e-4, 100.0)
"""Allowed box sides, radii and lengths [m]."""
MAX_ANGLE_RAD = 100.0
"""Largest |roll|, |pitch|, |yaw| [rad]."""
SCALE_RANGE = (1e-6, 1e3)
"""Allowed scale factors of a mesh file."""
MAX_MESH_BYTES = 50_000_000
"""Largest mesh file [bytes]."""
MAX_MESH_VERTICES = 1_000_000
"""Most vertices of a mesh (coal's bounding-volume tree of a million vertices takes ~1 GB)."""
MAX_NAME_CHARS = 100
"""Longest obstacle name (names appear in every message about the obstacle)."""
