"""Benchmark of the septic smoothing spline solve (issue: septic spline).

Prints median times for 5 joints at N = 4 (the paper's) and N = 10,000 segments:

- one-shot ``fit_septic_spline`` (assemble, factorise, solve, build the trajectory); the
  index structure of a problem size is cached after its first use, so a *cold* row with
  the cache cleared before every run is printed too;
- a prepared ``SepticSplineSolver``: ``solve`` of 5 joints, and ``solve_batch`` of 50
  candidates x 5 joints (one firefly iteration of the paper case).

Targets (one-shot): <= 100 us at N = 4 and <= 50 ms at N = 10,000.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

from planning.cli.arguments import COUNT
from planning.curves import banded_system
from planning.curves.spline import SepticSplineSolver, fit_septic_spline
from planning.curves.spline_settings import SplineSettings


def median_seconds(
    fn: Callable[[], object], repeats: int, before: Callable[[], object] | None = None
) -> float:
    fn()  # warm-up
    times = []
    for _ in range(repeats):
        if before is not None:
            before()
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure(
    n: int, repeats: int, settings: SplineSettings, rng: np.random.Generator
) -> list[tuple[str, float, float | None]]:
    """(label, median seconds, 1 if the row is held to the target else None) for N = n."""
    knots = np.linspace(0.0, float(n), n + 1)
    values = rng.normal(size=(n + 1, 5))
    batch = rng.normal(size=(n + 1, 250))
    solver = SepticSplineSolver(knots, settings)

    def one_shot() -> object:
        return fit_septic_spline(knots, values, settings)

    return [
        ("one-shot fit", median_seconds(one_shot, repeats), 1.0),
        (
            "one-shot fit, structure cache cold",
            median_seconds(one_shot, repeats, banded_system.structure.cache_clear),
            None,
        ),
        ("prepared solver: solve", median_seconds(lambda: solver.solve(values), repeats), None),
        (
            "prepared solver: solve_batch 50 x 5 joints",
            median_seconds(lambda: solver.solve_batch(batch), repeats),
            None,
        ),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=COUNT, default=300)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    settings = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0))
    print(f"{'case':51s} {'median':>12s} {'target':>10s}  verdict")
    for n, target in ((4, 100e-6), (10_000, 50e-3)):
        repeats = args.repeats if n < 100 else max(5, args.repeats // 30)
        for label, seconds, limit in measure(n, repeats, settings, rng):
            verdict = "" if limit is None else ("met" if seconds <= limit * target else "NOT met")
            limit_text = "" if limit is None else f"{target * 1e6:7.0f} us"
            print(f"N = {n:<6d} {label:42s} {seconds * 1e6:9.1f} us {limit_text:>10s}  {verdict}")


if __name__ == "__main__":
    main()
