"""Parameters of the firefly algorithm (:mod:`planning.search.firefly`) and their bounds.

Apart from the algorithm, whose compiled sweep loads numba: reading settings (a scene file)
needs none of it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from planning.errors import PlanningError
from planning.validation import integer_in, number_in, shown

Mode = Literal["sweep", "sequential"]


MAX_FIREFLIES = 1000
"""Largest population: a sweep draws ``n^2 d`` kicks per iteration (1000^2 x 15 x 8 bytes =
120 MB at the largest), and the sequential mode evaluates ``n^2`` candidates one by one."""
MAX_ITERATIONS = 10_000
"""Most iterations."""
MAX_EVALUATIONS = 1_000_000
"""Most evaluations, ``fireflies x (iterations + 1)``: it bounds how long a scene can ask the
search to run (minutes on two cores, ``docs/benchmarks.md``)."""
MAX_STEP = 10.0
"""Largest ``alpha`` and ``beta0`` [normalised units]: beyond 1 every move already leaves the
box and is clipped back, so larger values only hide a typo."""
MAX_GAMMA = 1000.0
"""Largest light absorption: at 1000 a firefly sees no neighbour farther than 0.1."""


@dataclass(frozen=True)
class FireflySettings:
    """Parameters of the firefly algorithm; validated on construction.

    Attributes:
        fireflies: population size n, in [2, :data:`MAX_FIREFLIES`]. The paper: 50.
        iterations: number of iterations T, in [0, :data:`MAX_ITERATIONS`]. The paper: 50.
            ``fireflies x (iterations + 1)`` is at most :data:`MAX_EVALUATIONS`.
        alpha: initial randomisation strength, in normalised units, in [0, 10]. The paper: 1.
        beta0: attractiveness at distance 0, in [0, 10]. The paper: 0.5.
        gamma: light absorption, in normalised units, in [0, 1000].
        theta: per-iteration decay of alpha, in (0, 1].
        mode: ``"sweep"`` or ``"sequential"`` (see the module docstring).
        stall_iterations: stop early once this many iterations in a row have improved the
            best value by less than :data:`~planning.search.optimizer.STALL_TOLERANCE` of it;
            0 (default, the paper): run every iteration. Deterministic: the same seed stops
            at the same iteration.
    """

    fireflies: int = 50
    iterations: int = 50
    alpha: float = 1.0
    beta0: float = 0.5
    gamma: float = 1.0
    theta: float = 0.97
    mode: Mode = "sweep"
    stall_iterations: int = 0

    @property
    def evaluations(self) -> int:
        """The evaluation budget of a run to the last iteration: ``fireflies x (iterations + 1)``."""
        return self.fireflies * (self.iterations + 1)

    def __post_init__(self) -> None:
        integer_in("fireflies", self.fireflies, 2, MAX_FIREFLIES)
        integer_in("iterations", self.iterations, 0, MAX_ITERATIONS)
        if self.evaluations > MAX_EVALUATIONS:
            raise PlanningError(
                f"fireflies x (iterations + 1) = {self.evaluations} evaluations; at most {MAX_EVALUATIONS}: "
                "lower fireflies or iterations"
            )
        number_in("alpha", self.alpha, 0.0, MAX_STEP)
        number_in("beta0", self.beta0, 0.0, MAX_STEP)
        number_in("gamma", self.gamma, 0.0, MAX_GAMMA)
        number_in("theta", self.theta, 0.0, 1.0, low_open=True)
        integer_in("stall_iterations", self.stall_iterations, 0, MAX_ITERATIONS)
        if self.mode not in ("sweep", "sequential"):
            raise PlanningError(f"mode = {shown(self.mode)}; allowed: 'sweep', 'sequential'")
