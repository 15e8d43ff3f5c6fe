"""Benchmark of the torque-limited timing: payloads on the CPR, the Panda and the UR5.

Per robot, problem and payload (a point mass 5 cm out along the tool's z axis), in one run
and one process (warm library calls):

- ours: the scene planned with the payload; its duration, and whether every joint torque is
  within its effort limit at every 1 ms sample (RNEA, as ``cpr-plan check`` computes them);
- TOPP-RA (``toppra``, velocity, acceleration and torque constraints, no jerk limit) on the
  same path (our trajectory's, in arc length): the time-optimal duration of that path
  without a jerk limit, a lower bound for it;
- the timing alone, on the path the planner timed: wall time and duration with the torque
  limits and without them (today's kinematic timing);
- the jerk's own cost: Ruckig's time-optimal jerk-limited motion from start to goal (no
  obstacle, no torque: a lower bound of any jerk-limited trajectory) over TOPP-RA's jerk-free
  time along the straight line between them. Where it exceeds 1.10, no jerk-limited
  trajectory meets "duration <= 1.10 x TOPP-RA" there; the duration is also given over
  ``max(TOPP-RA bound, Ruckig bound)``, the bound of a robot whose jerk or torque binds,
  and over the TOPP-RA bound times that straight line's jerk cost (an estimate of the path's
  jerk-limited optimum, not a bound: none computes it exactly with torques).

Problems: ``--scenes`` generated CPR scenes (``generate_scenes``, seed ``--scene-seed``) and
the first ``--limit`` problems of each MotionBenchMaker class whose start and goal are valid
(:mod:`planning.bench.mbm`, downloaded once). Prints per robot and payload: plans, share within
the effort limits, median duration / TOPP-RA bound, median duration over the same problem's
without payload, and the timing's median and p95 wall time with and without torque limits;
writes ``torque.csv`` and ``torque.md`` to ``--out``. Needs the ``bench`` extra (toppra).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import statistics
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

import cpr_kin as ck
from planning.bench.mbm import CLASSES, endpoint_violations, import_problem, problems
from planning.bench.problem_selection import check_limit
from planning.bench.ruckig_bound import free_space_bound
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SEED
from planning.curves.path_timing import time_path
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError
from planning.io.report import markdown_table
from planning.io.scene_file import load_scene
from planning.pipeline.planner import plan
from planning.pipeline.scene import Scene
from planning.pipeline.torques import torque_profile
from planning.warming import warm_up

PAYLOADS_KG = {"cpr": (0.0, 2.0, 5.0), "panda": (0.0, 1.5, 3.0), "ur5": (0.0, 2.5, 5.0)}
"""The payloads of the issue, per robot [kg]."""
COM_IN_TCP_M = (0.0, 0.0, 0.05)
"""Where the payload's mass sits in the tool frame [m]."""


def cases(robot_name: str, args: argparse.Namespace) -> Iterator[tuple[str, Scene, ck.Robot]]:
    """``(name, scene, robot)`` of the robot's problems (module docstring)."""
    if robot_name == "cpr":
        robot = ck.load_cpr()
        for scene in generate_scenes(args.scenes, args.scene_seed, robot, narrow=args.scenes // 4):
            yield scene.name, scene, robot
        return
    loaded: ck.Robot | None = None
    for problem in problems(robot_name, CLASSES, args.limit):
        path = args.out / "scenes" / robot_name / f"{problem.name}.yaml"
        import_problem(problem, path)
        scene = load_scene(path)
        loaded = loaded or scene.robot.load()  # type: ignore[union-attr]
        if not endpoint_violations(scene, loaded):
            yield problem.name, scene, loaded


def toppra_bound(trajectory: Trajectory, robot: ck.Robot, dynamics: ck.Dynamics) -> float:
    """Time-optimal duration [s] of ``trajectory``'s path under velocity, acceleration and torque limits."""
    import toppra
    import toppra.algorithm
    import toppra.constraint

    limits = robot.limits
    t = np.linspace(trajectory.knots[0], trajectory.knots[-1], 4001)
    q = trajectory(t)
    steps = np.linalg.norm(np.diff(q, axis=0) / limits.velocity, axis=1)
    arc = np.concatenate([[0.0], np.cumsum(steps)])
    keep = np.concatenate([[True], steps > 1e-12])
    pick = np.unique(np.searchsorted(arc[keep], np.linspace(0.0, arc[-1], 400)).clip(0, keep.sum() - 1))
    s, points = arc[keep][pick], q[keep][pick]
    path = toppra.SplineInterpolator(s / s[-1], points)
    effort = np.where(np.isfinite(dynamics.effort), dynamics.effort, 1e9)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-limits.velocity, limits.velocity])),
        toppra.constraint.JointAccelerationConstraint(
            np.column_stack([-limits.acceleration, limits.acceleration])
        ),
        toppra.constraint.JointTorqueConstraint(
            lambda q, qd, qdd: dynamics.torques(q, qd, qdd)[0],
            np.column_stack([-effort, effort]),
            np.zeros(robot.nq),
        ),
    ]
    timed = toppra.algorithm.TOPPRA(constraints, path, gridpoints=np.linspace(0, 1, 1001)).compute_trajectory(
        0, 0
    )
    return float("nan") if timed is None else float(timed.duration)


def measure(name: str, scene: Scene, robot: ck.Robot, payload_kg: float) -> dict[str, Any]:
    """One problem planned with one payload (module docstring)."""
    loaded = dataclasses.replace(scene, payload=ck.Payload(payload_kg, COM_IN_TCP_M))
    row: dict[str, Any] = {"problem": name, "payload_kg": payload_kg}
    try:
        result = plan(loaded, robot)
    except NoSolutionError as exc:
        return row | {"ok": False, "why": str(exc)[:120]}
    dynamics, limits = result.problem.dynamics, robot.limits
    usage = torque_profile(dynamics, result.trajectory).peak_utilisation.max()
    path = result.spline.trajectory
    kinematic_s = _timed(lambda: time_path(path, limits.velocity, limits.acceleration, limits.jerk))
    torque_s = _timed(
        lambda: time_path(path, limits.velocity, limits.acceleration, limits.jerk, torque=dynamics)
    )
    q_start, q_goal = result.problem.q_start, result.problem.q_goal
    line = Trajectory(np.array([0.0, 1.0]), np.stack([q_start, q_goal - q_start], axis=-1)[None])
    return row | {
        "ok": True,
        "duration_s": result.trajectory.duration,
        "timing": result.metrics.timing,
        "peak_torque_usage": float(usage),
        "within_effort": bool(usage <= 1.0),
        "toppra_s": toppra_bound(result.trajectory, robot, dynamics),
        "ruckig_s": free_space_bound(result.problem),
        "toppra_line_s": toppra_bound(line, robot, dynamics),
        "timing_kinematic_s": kinematic_s[0],
        "timing_torque_s": torque_s[0],
        "path_kinematic_duration_s": kinematic_s[1],
        "path_torque_duration_s": torque_s[1],
    }


def _timed(timing: Any) -> tuple[float, float]:
    """``(median wall time of 3 runs [s], duration [s])`` of a timing call."""
    walls, duration = [], 0.0
    for _ in range(3):
        started = time.perf_counter()
        duration = timing().duration
        walls.append(time.perf_counter() - started)
    return statistics.median(walls), duration


def percentile(values: list[float], q: float) -> float:
    """The ``q``-th percentile of ``values`` (NaN when empty)."""
    return float(np.percentile(values, q)) if values else float("nan")


def summary(rows: list[dict[str, Any]], robot_name: str) -> list[tuple[str, ...]]:
    """The table rows of one robot, one per payload."""
    table: list[tuple[str, ...]] = []
    mine = [r for r in rows if r["robot"] == robot_name]
    bare = {r["problem"]: r for r in mine if r["payload_kg"] == 0.0 and r["ok"]}
    for payload in PAYLOADS_KG[robot_name]:
        group = [r for r in mine if r["payload_kg"] == payload]
        done = [r for r in group if r["ok"]]
        bound = [r["duration_s"] / r["toppra_s"] for r in done if np.isfinite(r["toppra_s"])]
        floor = [r["ruckig_s"] / r["toppra_line_s"] for r in done if np.isfinite(r["toppra_line_s"])]
        either = [r["duration_s"] / np.nanmax([r["toppra_s"], r["ruckig_s"]]) for r in done]
        jerk_cost = [
            r["duration_s"] * r["toppra_line_s"] / (r["toppra_s"] * r["ruckig_s"])
            for r in done
            if np.isfinite(r["toppra_s"] * r["toppra_line_s"])
        ]
        cost = [r["duration_s"] / bare[r["problem"]]["duration_s"] for r in done if r["problem"] in bare]
        path_cost = [r["path_torque_duration_s"] / r["path_kinematic_duration_s"] for r in done]
        torque_ms = [1e3 * r["timing_torque_s"] for r in done]
        kinematic_ms = [1e3 * r["timing_kinematic_s"] for r in done]
        table.append(
            (
                robot_name,
                f"{payload:g}",
                f"{len(done)}/{len(group)}",
                f"{sum(r['within_effort'] for r in done)}/{len(done)}",
                f"{percentile([r['peak_torque_usage'] for r in done], 50):.2f}",
                f"{percentile(bound, 50):.3f} ({max(bound, default=float('nan')):.3f})",
                f"{percentile(floor, 50):.3f} ({min(floor, default=float('nan')):.3f})",
                f"{percentile(either, 50):.3f}",
                f"{percentile(jerk_cost, 50):.3f}",
                f"{percentile(cost, 50):.3f}",
                f"{percentile(path_cost, 50):.3f}",
                f"{percentile(torque_ms, 50):.1f} / {percentile(torque_ms, 95):.1f}",
                f"{percentile(kinematic_ms, 50):.1f} / {percentile(kinematic_ms, 95):.1f}",
            )
        )
    return table


HEADERS = (
    "robot",
    "payload [kg]",
    "planned",
    "within effort (1 ms)",
    "median peak torque / effort",
    "duration / TOPP-RA bound, median (max)",
    "Ruckig / TOPP-RA on the straight line, median (min)",
    "duration / max(TOPP-RA, Ruckig), median",
    "duration / (TOPP-RA x the line's Ruckig / TOPP-RA), median",
    "duration / no payload's, median",
    "timing: torque / kinematic duration, median",
    "timing wall time, torque: median / p95 [ms]",
    "timing wall time, kinematic: median / p95 [ms]",
)


def main() -> int:
    """Run the benchmark (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", nargs="+", default=["cpr", "panda", "ur5"], choices=list(PAYLOADS_KG))
    parser.add_argument("--scenes", type=COUNT, default=12, help="generated CPR scenes")
    parser.add_argument("--scene-seed", type=SEED, default=31)
    parser.add_argument("--limit", type=COUNT, default=1, help="MotionBenchMaker problems per class")
    parser.add_argument("--out", type=Path, default=Path("out/bench_torque"))
    args = parser.parse_args()
    check_limit(parser, args.limit)
    args.out.mkdir(parents=True, exist_ok=True)
    warm_up()
    rows: list[dict[str, Any]] = []
    for robot_name in args.robots:
        for name, scene, robot in cases(robot_name, args):
            for payload in PAYLOADS_KG[robot_name]:
                row = {"robot": robot_name} | measure(name, scene, robot, payload)
                rows.append(row)
                shown = (
                    f"{row['duration_s']:.3f} s, torque {row['peak_torque_usage']:.2f}, "
                    f"/ TOPP-RA {row['duration_s'] / row['toppra_s']:.3f}"
                    if row["ok"]
                    else row["why"]
                )
                print(f"{robot_name} {name} {payload:g} kg: {shown}", flush=True)
    keys = list(dict.fromkeys(k for row in rows for k in row))
    with (args.out / "torque.csv").open("w", newline="") as out:
        writer = csv.DictWriter(out, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)
    table = [line for robot_name in args.robots for line in summary(rows, robot_name)]
    text = markdown_table(table, HEADERS)
    print("\n" + text)
    (args.out / "torque.md").write_text(text + "\n")
    print(f"\nrows: {args.out / 'torque.csv'}; table: {args.out / 'torque.md'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
