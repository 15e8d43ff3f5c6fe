"""Benchmark of the clearance queries of cpr_kin (issue: foundation).

Prints the median time of one clearance query (6 robot geometries vs 1 obstacle) and,
per configuration, of batches of 1,000 configurations: per-group distances
(``clearance_batch``) and the parallel yes/no margin check (``margin_violated``).
Target: <= 10 us per configuration in a batch.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable

import numpy as np

import cpr_kin as ck
from planning.cli.arguments import COUNT


def median_seconds(fn: Callable[[], object], repeats: int) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=COUNT, default=15)
    parser.add_argument("--batch", type=COUNT, default=1000)
    args = parser.parse_args()

    robot = ck.load_cpr()
    world = ck.CollisionWorld(robot, [ck.Obstacle.box((0.3, 0.3, 0.3), (0.0, 0.6, 0.15), name="crate")])
    rng = np.random.default_rng(0)
    batch = rng.uniform(robot.limits.lower, robot.limits.upper, (args.batch, robot.nq))
    single = batch[:1]
    world.margin_violated(single, 0.1)  # build the thread pool outside the timing

    rows = [
        (
            "clearance(q): all pairs, closest points",
            median_seconds(lambda: world.clearance(batch[0]), 2000),
            1,
        ),
        ("clearance_batch, 1 configuration", median_seconds(lambda: world.clearance_batch(single), 2000), 1),
        (
            f"clearance_batch, {args.batch} configurations",
            median_seconds(lambda: world.clearance_batch(batch), args.repeats),
            args.batch,
        ),
        (
            f"margin_violated ({world.num_threads} threads), {args.batch} configurations",
            median_seconds(lambda: world.margin_violated(batch, 0.1), args.repeats),
            args.batch,
        ),
    ]
    print(f"robot geometries: {len(robot.geometries)}, obstacles: 1, pairs: {len(world.pairs)}")
    print(f"{'query':55s} {'median total':>14s} {'per configuration':>18s}")
    for label, seconds, count in rows:
        print(f"{label:55s} {seconds * 1e3:11.3f} ms {seconds / count * 1e6:15.2f} us")
    per_config = rows[2][1] / args.batch * 1e6
    verdict = "met" if per_config <= 10 else "NOT met"
    print(f"target <= 10 us per configuration in a batch: {per_config:.2f} us -> {verdict}")


if __name__ == "__main__":
    main()
