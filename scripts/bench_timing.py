"""Benchmark of the timing: how close to the robot's limits the planned trajectories run.

Per scene (``--scenes`` generated from ``--scene-seed``, the bundled ones, and the paper case
with its duration freed), in one run and one process (warm library calls):

- ours: the trajectory's duration, how it was timed (``fastest``, or the fallbacks
  ``narrowed`` and ``uniform``), the wall time of the timing step (the chosen path's
  timings, the narrowed ones included when the fastest failed the check), and the uniform
  timing of the same path (what the planner executed before);
- Ruckig: the time-optimal jerk-limited rest-to-rest duration from start to goal under the
  same limits with no obstacle at all, a lower bound no trajectory can beat;
- OMPL RRT-Connect + simplification + TOPP-RA (velocity and acceleration only): its
  duration and its largest jerk over the jerk limit;
- whether the straight joint-space line from start to goal keeps the margin (``clear``),
  where the lower bound is nearly reachable, or not (``blocked``).

Then the medians: ours / Ruckig over all scenes, clear and blocked ones (targets 1.3 and
1.1), ours against OMPL + TOPP-RA on the scenes both solve, beside the Ruckig bound's median
on those scenes (every jerk-limited trajectory lasts at least its scene's bound, so no
jerk-limited planner's median duration can be below the bounds' median: when that is above
OMPL + TOPP-RA's, the target "ours <= theirs" cannot be met), the timing step's wall time
(target 50 ms); and, on ``--paths`` random paths, how often raising one limit (by 1.2x,
2x) slows the timing of the same path, and by how much at worst.

Needs the ``bench`` extra (ruckig, ompl, toppra). Prints the tables and writes them as
Markdown to ``--out``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import cpr_kin as ck
from planning.bench.ompl_rrt import plan_rrt_connect
from planning.bench.ruckig_bound import free_space_bound
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SECONDS, SEED
from planning.curves.path_timing import time_path
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.curves.spline_settings import SplineSettings
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import duration_free_scenes
from planning.io.report import markdown_table, text_table
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.timing import narrowed_timings, uniform_scale
from planning.warming import warm_up


@dataclass(frozen=True)
class Row:
    """One scene's figures (durations [s]; NaN where a planner failed)."""

    scene: str
    clear: bool
    bound_s: float
    ours_s: float
    method: str
    uniform_s: float
    timing_ms: float
    ompl_s: float
    ompl_jerk: float


def line_is_clear(scene: Scene, robot: ck.Robot) -> bool:
    """The straight joint-space line from start to goal keeps the margin (certified)."""
    problem = build_problem(scene, robot)
    q0, q1 = problem.q_start, problem.q_goal
    check = ck.check_curve(
        problem.world,
        lambda t: q0 + np.asarray(t)[:, None] * (q1 - q0),
        0.0,
        1.0,
        np.abs(q1 - q0),
        scene.safety_margin,
        scene.planner.verify_step_m,
    )
    return bool(check.accepted)


def measure(scene: Scene, robot: ck.Robot, rrt_time_s: float) -> Row:
    problem = build_problem(scene, robot)
    bound = free_space_bound(problem)
    clear = line_is_clear(scene, robot)
    nan = float("nan")
    ours = uniform = timing_ms = nan
    method = "failed"
    try:
        result = plan(scene, robot)
        ours, method = result.trajectory.duration, result.metrics.timing
        uniform = result.spline.trajectory.time_scaled(uniform_scale(result.spline, result.problem)).duration
        started = time.perf_counter()
        offered = result.problem.duration.timings(result.problem, result.waypoints)  # the step again, alone
        if method != "fastest":  # the fastest timing failed the check: the fallbacks were computed
            narrowed_timings(
                result.problem, offered, result.problem.scene.planner.tuning.narrowed_acceleration
            )
        timing_ms = 1e3 * (time.perf_counter() - started)
    except (PlanningError, NoSolutionError):
        pass
    peer = plan_rrt_connect(scene, robot, time_limit_s=rrt_time_s, seed=scene.planner.seed)
    ompl, jerk = (peer.duration, peer.jerk_over_limit) if peer.success else (nan, nan)
    return Row(scene.name, clear, bound, ours, method, uniform, timing_ms, ompl, jerk)


def median(values: list[float]) -> float:
    finite = [v for v in values if np.isfinite(v)]
    return statistics.median(finite) if finite else float("nan")


def monotonicity(robot: ck.Robot, paths: int, seed: int) -> tuple[int, int, float]:
    """``(raises, slower, worst)``: limits raised one at a time on random paths."""
    limits = robot.limits
    base = (limits.velocity, limits.acceleration, limits.jerk)
    rest = SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
    rng = np.random.default_rng(seed)
    ratios = []
    for index in range(paths):
        a, b = rng.uniform(limits.lower, limits.upper, size=(2, robot.nq))
        b = a + rng.uniform(0.05, 1.0) * (b - a)
        middle = rng.uniform(limits.lower, limits.upper)
        nodes = (
            np.linspace(a, b, 4) if index % 2 == 0 else np.array([a, (a + middle) / 2, (middle + b) / 2, b])
        )
        path = SepticSplineSolver(uniform_knots(3, 3.0), rest).solve(nodes).trajectory
        before = time_path(path, *base).duration
        for which in range(3):
            for factor in (1.2, 2.0):
                v, a, j = (limit * (factor if n == which else 1.0) for n, limit in enumerate(base))
                ratios.append(time_path(path, v, a, j).duration / before)
    slower = [r for r in ratios if r > 1 + 1e-9]
    return len(ratios), len(slower), max(ratios)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=COUNT, default=50, help="generated scenes (default: 50)")
    parser.add_argument("--scene-seed", type=SEED, default=0, help="seed of the scene generator (default: 0)")
    parser.add_argument(
        "--rrt-time", type=SECONDS, default=2.0, help="RRT-Connect time limit [s] (default: 2)"
    )
    parser.add_argument("--paths", type=COUNT, default=40, help="random paths of the monotonicity check")
    parser.add_argument("--out", type=Path, default=Path("out/bench_timing.md"), help="Markdown report")
    args = parser.parse_args()

    robot = ck.load_cpr()
    warm_up(robot)
    scenes = generate_scenes(args.scenes, args.scene_seed, robot)
    scenes += duration_free_scenes()
    rows = []
    for scene in scenes:
        rows.append(row := measure(scene, robot, args.rrt_time))
        print(
            f"  {row.scene:22s} {'clear' if row.clear else 'blocked':7s} bound {row.bound_s:.3f} s  "
            f"ours {row.ours_s:.3f} s ({row.method}, x{row.ours_s / row.bound_s:.2f})  "
            f"OMPL+TOPP-RA {row.ompl_s:.3f} s (jerk x{row.ompl_jerk:.0f})",
            flush=True,
        )

    def solved(subset: list[Row], field: str = "ours_s") -> int:
        return sum(bool(np.isfinite(getattr(r, field))) for r in subset)

    def ratio(subset: list[Row]) -> str:
        return f"{median([r.ours_s / r.bound_s for r in subset]):.3f} (n={solved(subset)})"

    both = [r for r in rows if np.isfinite(r.ours_s) and np.isfinite(r.ompl_s)]
    raises, slower, worst = monotonicity(robot, args.paths, args.scene_seed)
    summary = [
        (
            "scenes planned: ours / OMPL+TOPP-RA",
            f"{solved(rows)} / {solved(rows, 'ompl_s')} of {len(rows)}",
            "-",
        ),
        ("median duration / Ruckig bound, all", ratio(rows), "<= 1.3"),
        ("  straight line clear", ratio([r for r in rows if r.clear]), "<= 1.1"),
        ("  straight line blocked", ratio([r for r in rows if not r.clear]), "-"),
        (
            "median uniform timing of our path / bound (before)",
            f"{median([r.uniform_s / r.bound_s for r in rows]):.3f}",
            "2.3 (issue)",
        ),
        (
            "timed fastest / narrowed / uniform (fallbacks)",
            " / ".join(str(sum(r.method == m for r in rows)) for m in ("fastest", "narrowed", "uniform"))
            + f" of {solved(rows)}",
            "-",
        ),
        (
            "median duration on scenes both solve: ours / OMPL+TOPP-RA",
            f"{median([r.ours_s for r in both]):.3f} s / {median([r.ompl_s for r in both]):.3f} s "
            f"(ratio {median([r.ours_s for r in both]) / median([r.ompl_s for r in both]):.3f}; "
            f"per scene {median([r.ours_s / r.ompl_s for r in both]):.3f}; n={len(both)})",
            "ours <= theirs",
        ),
        (
            "  the jerk-limited floor there: median Ruckig bound",
            f"{median([r.bound_s for r in both]):.3f} s (ratio to OMPL+TOPP-RA "
            f"{median([r.bound_s for r in both]) / median([r.ompl_s for r in both]):.3f})",
            "-",
        ),
        (
            "  scenes where OMPL+TOPP-RA beats that bound (it ignores jerk)",
            f"{sum(r.ompl_s < r.bound_s for r in both)} of {len(both)}",
            "-",
        ),
        (
            "OMPL+TOPP-RA peak jerk / limit, median (ours: <= 1)",
            f"{median([r.ompl_jerk for r in both]):.0f}",
            "-",
        ),
        (
            "timing step wall time, median (max)",
            f"{median([r.timing_ms for r in rows]):.1f} ms ({np.nanmax([r.timing_ms for r in rows]):.1f} ms)",
            "<= 50 ms",
        ),
        (
            f"raised limits that slow a path ({args.paths} random paths)",
            f"{slower} of {raises}, worst {100 * (worst - 1):+.1f} %",
            "-",
        ),
    ]
    headers = ("figure", "measured", "target")
    table = [
        (
            r.scene,
            "clear" if r.clear else "blocked",
            f"{r.bound_s:.3f}",
            f"{r.ours_s:.3f}",
            f"{r.ours_s / r.bound_s:.2f}",
            r.method,
            f"{r.uniform_s:.3f}",
            f"{r.timing_ms:.1f}",
            f"{r.ompl_s:.3f}",
            f"{r.ompl_jerk:.0f}",
        )
        for r in rows
    ]
    columns = (
        "scene",
        "line",
        "Ruckig [s]",
        "ours [s]",
        "ours/Ruckig",
        "timing",
        "uniform [s]",
        "timing [ms]",
        "OMPL+TOPP-RA [s]",
        "its jerk/limit",
    )
    print()
    print(text_table(summary, headers))
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(
        "# Timing benchmark\n\n"
        + markdown_table(summary, headers)
        + "\n\n"
        + markdown_table(table, columns)
        + "\n"
    )
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
