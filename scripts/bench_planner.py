"""Benchmark of the paper case end to end (issue: firefly planner).

Plans the paper case (n = 50, 50 iterations, sweep mode) for several seeds and prints the
median wall time of the whole :func:`planning.pipeline.planner.plan` call and of its firefly search,
with the evaluation count. Target: <= 0.5 s end to end on 2 cores; goal: <= 0.1 s.
"""

from __future__ import annotations

import argparse
import statistics

import cpr_kin as ck
from planning.cli.arguments import COUNT
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=COUNT, default=7, help="seeds 0..runs-1 (default: 7)")
    args = parser.parse_args()
    robot = ck.load_cpr()
    plan(paper_scene(0), robot)  # warm-up: imports, caches, thread pool
    total, search, evaluations = [], [], []
    for seed in range(args.runs):
        metrics = plan(paper_scene(seed), robot).metrics
        total.append(metrics.planning_time_s)
        search.append(metrics.optimiser_time_s)
        evaluations.append(metrics.evaluations)
    end_to_end = statistics.median(total)
    print(f"paper case, {args.runs} seeds, n = 50, 50 iterations, sweep mode, {evaluations[0]} evaluations")
    print(f"  end to end (median)     {end_to_end:.3f} s   [min {min(total):.3f}, max {max(total):.3f}]")
    print(f"  firefly search (median) {statistics.median(search):.3f} s")
    print(f"  per evaluation          {statistics.median(search) / evaluations[0] * 1e6:.0f} us")
    target = "met" if end_to_end <= 0.5 else "NOT met"
    goal = "met" if end_to_end <= 0.1 else "not met"
    print(f"  target <= 0.5 s: {target}; goal <= 0.1 s: {goal}")
    print("  paper: 53 s for the FMA alone")


if __name__ == "__main__":
    main()
