"""The start-up floor of a ``cpr-plan`` process: what the planner stands on, before a line of ours runs.

    python scripts/startup_floor.py

Imports Pinocchio, coal, SciPy's linear algebra and numba, as the planner does, and calls one
trivial compiled kernel, cached on disk like the planner's (its first run compiles it): numba's
first call of any cached kernel loads its typing and lowering registries, a cost of its own that
every process using a compiled kernel pays once. ``cpr-plan plan``'s wall time less this one's is
what the planner itself adds (docs/benchmarks.md: the new-process row).
"""

from __future__ import annotations

import coal  # noqa: F401 - imported for its start-up cost
import numpy as np
import pinocchio  # noqa: F401
import scipy.linalg  # noqa: F401
from numba import njit


@njit(cache=True)
def _total(values: np.ndarray) -> float:
    return float(values.sum())


if __name__ == "__main__":
    _total(np.ones(3))
