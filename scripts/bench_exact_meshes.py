"""MotionBenchMaker on the exact link meshes beside the convex hulls alone, problem by problem, in one run.

    python scripts/bench_exact_meshes.py [--robots ur5 panda] [--limit N --sample-seed S]
                                         [--time-limit SECONDS] [--within SECONDS] [--out DIR]
                                         [--models meshes]

Each problem is imported as ``import-moveit`` writes it (:func:`planning.bench.mbm.import_problem`)
and planned warm, in this one process, twice, in alternating order: by the robot as it loads
(its concave links' exact meshes deciding, planned on the hulls first:
:func:`planning.pipeline.hulls_first.on_hulls`) and by the same robot with the exact meshes
removed (the hulls alone: the collision model before the meshes). A problem counts as valid
on a model when its start and goal clear the margins there
(:func:`planning.bench.mbm.endpoint_violations`); every trajectory is checked as ``cpr-plan check``
checks it, on the exact meshes. Prints per class: problems, valid on each model, planned,
passing the check, median and p95 planning time on each, and the ratio of the medians on the
problems valid on both; with ``--within S``, the planned cell also says how many took under
``S`` seconds (a longer ``--time-limit`` shows what a limit of ``S`` leaves out). ``--models
meshes`` plans on the meshes alone (validity is still counted on both): half the time, for a
robot whose figure is what the meshes plan, not the ratio.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import cpr_kin as ck
from planning.bench.mbm import endpoint_violations, import_problem
from planning.bench.problem_selection import add_selection, check_selection, selected_problems
from planning.cli.arguments import SECONDS
from planning.errors import CprPlanError
from planning.io.scene_file import load_scene
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.verification import verify_for_scene
from planning.warming import warm_up

MODELS = ("hulls", "meshes")


def planned(scene: Any, robot: ck.Robot, exact: ck.Robot) -> dict[str, Any]:
    """One plan of ``scene`` by ``robot``: ok, planning time [s], passing the check on ``exact``."""
    started = time.perf_counter()
    try:
        result = plan(scene, robot)
    except (CprPlanError, ck.CprKinError):  # no trajectory, an end out of reach, ...: not planned
        return {"ok": False, "time_s": time.perf_counter() - started, "checked": False}
    time_s = time.perf_counter() - started
    checked = not verify_for_scene(build_problem(scene, exact), result.trajectory).problems
    return {"ok": True, "time_s": time_s, "checked": checked}


def rows_of(args: argparse.Namespace, robot_name: str, out: Path) -> list[dict[str, Any]]:
    """Every selected problem of ``robot_name`` on both models (module docstring)."""
    rows: list[dict[str, Any]] = []
    robots: dict[str, ck.Robot] = {}
    for k, problem in enumerate(selected_problems(args, robot_name)):
        scene = load_scene(import_problem(problem, out / robot_name / f"{problem.name}.yaml"))
        scene = dataclasses.replace(scene, planner=scene.planner.updated(time_limit_s=args.time_limit))
        if not robots:
            assert scene.robot is not None  # an imported scene names its robot
            robots["meshes"] = scene.robot.load()
            robots["hulls"] = dataclasses.replace(robots["meshes"], exact_meshes={})
            warm_up(robots["meshes"])
        row: dict[str, Any] = {"class": problem.problem_class, "name": problem.name}
        for model in MODELS:
            row[f"{model}_valid"] = not endpoint_violations(scene, robots[model])
        for model in MODELS if k % 2 == 0 else MODELS[::-1]:  # alternating which goes first
            if row[f"{model}_valid"] and model in args.models:
                row |= {
                    f"{model}_{key}": value
                    for key, value in planned(scene, robots[model], robots["meshes"]).items()
                }
        rows.append(row)
        said = "  ".join(f"{m} {row.get(f'{m}_ok', '-')} {row.get(f'{m}_time_s', 0.0):.2f} s" for m in MODELS)
        print(f"{robot_name} {problem.name}: {said}", file=sys.stderr, flush=True)
    return rows


def table(robot_name: str, rows: list[dict[str, Any]], within_s: float | None = None) -> list[str]:
    """The markdown rows of ``robot_name`` per class and for all (module docstring)."""
    lines = []
    for group in [*dict.fromkeys(r["class"] for r in rows), "all"]:
        chosen = [r for r in rows if group in ("all", r["class"])]
        cells = [robot_name, group, str(len(chosen))]
        for model in MODELS:
            valid = [r for r in chosen if r[f"{model}_valid"]]
            tried = [r for r in valid if f"{model}_ok" in r]
            solved = [r for r in tried if r[f"{model}_ok"]]
            checked = sum(1 for r in solved if r[f"{model}_checked"])
            times = [r[f"{model}_time_s"] for r in solved]
            spread = f"{np.median(times):.3f} ({np.percentile(times, 95):.3f})" if times else "-"
            count = str(len(solved))
            if within_s is not None:
                count += f" ({sum(1 for t in times if t < within_s)} < {within_s:g} s)"
            cells += [str(len(valid))] + ([count, str(checked), spread] if tried else ["-"] * 3)
        both = [r for r in chosen if r.get("hulls_ok") and r.get("meshes_ok")]
        ratio = (
            statistics.median(r["meshes_time_s"] for r in both)
            / statistics.median(r["hulls_time_s"] for r in both)
            if both
            else float("nan")
        )
        cells += [f"{ratio:.2f} ({len(both)})" if both else "-"]  # one model planned: no ratio
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_selection(parser)
    parser.add_argument("--time-limit", type=SECONDS, default=10.0, help="each plan's time_limit_s [s]")
    parser.add_argument("--within", type=SECONDS, help="also count the plans that took under SECONDS [s]")
    parser.add_argument("--out", type=Path, help="folder for the scene files (default: a temporary one)")
    parser.add_argument("--models", nargs="+", choices=MODELS, default=list(MODELS), help="models planned")
    args = parser.parse_args()
    check_selection(parser, args)
    out = args.out or Path(tempfile.mkdtemp(prefix="mbm-exact-"))
    lines = [
        "| robot | class | problems | valid on hulls | planned | passing `check` | median (p95) [s] "
        "| valid on meshes | planned | passing `check` | median (p95) [s] "
        "| ratio meshes / hulls (both planned) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for robot_name in args.robots:
        lines += table(robot_name, rows_of(args, robot_name, out), args.within)
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
