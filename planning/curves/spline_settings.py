"""Settings of the septic smoothing spline (:mod:`planning.curves.spline`), validated on construction.

Apart from the solver so that reading settings (a scene file) needs NumPy only.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from planning.errors import SplineError

Ends = Literal["natural", "rest"]


@dataclass(frozen=True)
class SplineSettings:
    """Settings of the septic smoothing spline; validated on construction.

    Attributes:
        p: node weight ``p_i`` (> 0; ``inf`` interpolates exactly), one value for every node
            or one per node. The paper: 1e6.
        a: ``(a1, a2, a3)`` weights (>= 0, not all zero) of the squared velocity,
            acceleration and jerk integrals. The paper: ``(0, 0, 1)``.
        ends: ``"natural"`` (the paper) or ``"rest"`` (zero velocity and acceleration at
            both ends).
        exact_ends: meet the first and last node exactly whatever ``p`` (default ``True``).

    """

    p: float | tuple[float, ...] = 1e6
    a: tuple[float, float, float] = (0.0, 0.0, 1.0)
    ends: Ends = "natural"
    exact_ends: bool = True

    def __post_init__(self) -> None:
        p = np.atleast_1d(np.asarray(self.p, dtype=float))
        if p.ndim != 1 or np.any(np.isnan(p)) or np.any(p <= 0):
            raise SplineError(f"spline weight p = {np.asarray(self.p).tolist()} must be > 0 (inf: exact)")
        object.__setattr__(self, "p", float(p[0]) if np.ndim(self.p) == 0 else tuple(float(x) for x in p))
        a = np.asarray(self.a, dtype=float)
        if a.shape != (3,) or not np.all(np.isfinite(a)) or np.any(a < 0):
            raise SplineError(
                f"spline weights a = {np.asarray(self.a).tolist()} must be three finite numbers >= 0"
            )
        if not np.any(a > 0):
            raise SplineError(
                "spline weights a = [0, 0, 0] leave the spline undetermined (singular system); "
                "give a velocity, acceleration or jerk weight > 0, e.g. a = [0, 0, 1]"
            )
        object.__setattr__(self, "a", (float(a[0]), float(a[1]), float(a[2])))
        if self.ends not in ("natural", "rest"):
            raise SplineError(f"spline ends = {self.ends!r}; allowed: 'natural', 'rest'")

    def scaled_for_time(self, scale: float) -> SplineSettings:
        """Settings that, on knots stretched by ``scale``, give the same node values.

        The ``a_r`` term carries ``h^(1 - 2r)``, so ``a_r`` scales by ``scale^(2r - 1)``.
        """
        a1, a2, a3 = self.a
        return SplineSettings(
            p=self.p, a=(a1 * scale, a2 * scale**3, a3 * scale**5), ends=self.ends, exact_ends=self.exact_ends
        )
