"""The CMA-ES's default parameters (Hansen 2016, "The CMA Evolution Strategy: A Tutorial", sec. A).

The population size and the recombination weights and covariance learning rates that
:mod:`planning.search.refinement` uses, with and without the active covariance update.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def population_size(dimension: int) -> int:
    """CMA-ES's default population for ``dimension`` variables: ``4 + floor(3 ln d)``."""
    return 4 + int(3 * math.log(dimension))


@dataclass(frozen=True)
class LearningRates:
    """The CMA-ES's recombination weights and covariance learning rates (Hansen 2016, sec. A).

    The best half of a generation moves the mean and teaches the covariance its steps
    (``weights``, summing to 1); with the active update, the worse half unteaches theirs
    (``negative_weights``, summing to ``-min(1 + c_1 / c_mu, 1 + 2 mu_eff^- / (mu_eff + 2),
    (1 - c_1 - c_mu) / (d c_mu))``, the last bound keeping the covariance positive definite).
    """

    weights: FloatArray
    """``(mu,)`` positive weights of the best half, best first."""
    negative_weights: FloatArray
    """``(lambda - mu,)`` weights (<= 0) of the worse half, best first; zeros without the
    active update."""
    mu_eff: float
    """Variance-effective selection mass of the positive weights."""
    c_1: float
    """Rank-one learning rate."""
    c_mu: float
    """Rank-mu learning rate."""

    @classmethod
    def of(cls, dimension: int, active: bool = True) -> LearningRates:
        """The default rates for ``dimension`` variables and :func:`population_size`."""
        d, lam = dimension, population_size(dimension)
        mu = lam // 2
        raw = math.log((lam + 1) / 2) - np.log(np.arange(1, lam + 1))  # > 0 for the best mu
        weights = raw[:mu] / raw[:mu].sum()
        mu_eff = 1.0 / float(np.sum(weights**2))
        c_1 = 2 / ((d + 1.3) ** 2 + mu_eff)
        c_mu = min(1 - c_1, 2 * (mu_eff - 2 + 1 / mu_eff) / ((d + 2) ** 2 + mu_eff))
        worse = raw[mu:]
        mu_eff_negative = float(worse.sum() ** 2 / np.sum(worse**2))
        mass = min(1 + c_1 / c_mu, 1 + 2 * mu_eff_negative / (mu_eff + 2), (1 - c_1 - c_mu) / (d * c_mu))
        negative = mass * worse / np.abs(worse).sum() if active else np.zeros(lam - mu)
        return cls(weights, negative, mu_eff, c_1, c_mu)
