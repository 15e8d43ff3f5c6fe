"""``cpr-plan``: plan, check and report trajectories from the command line.

Exit codes: 0 success; 2 invalid input (missing file, broken YAML, schema error, start or
goal unreachable or inside the margin, bad parameters, unwritable output); 3 no
collision-free trajectory found (``plan``, ``paper``) or a trajectory that fails the scene
(``check``). Errors are one line on stderr, never a traceback; on failure nothing is written.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import shutil
import signal
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import cpr_kin as ck  # lazy (lazy_loader): only the modules a command uses are imported
from planning.errors import PlanningError

if TYPE_CHECKING:
    from planning.scene import Scene
    from planning.search.firefly import FireflyProgress

# Each command imports what it needs when it runs: `cpr-plan batch`'s parent process only
# dispatches scenes to workers and so starts without the planner, coal or numba.

EXIT_OK, EXIT_INVALID, EXIT_NO_TRAJECTORY = 0, 2, 3


class _CommandError(Exception):
    """A failure with its exit code and one-line message."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


def _terminal_bar(total: int, desc: str, unit: str, leave: bool = True) -> Any:
    """A tqdm bar sized to the terminal.

    A terminal that reports a size of 0 (a bare pty) would make tqdm draw nothing.
    """
    from tqdm import tqdm

    size = shutil.get_terminal_size((80, 24))
    return tqdm(total=total, desc=desc, unit=unit, leave=leave, ncols=size.columns, nrows=size.lines)


def _progress(enabled: bool) -> tuple[Callable[[FireflyProgress], None] | None, Callable[[], None]]:
    """A tqdm bar over the firefly iterations when enabled (stdout is a terminal)."""
    if not enabled:
        return None, lambda: None
    bar: Any = None

    def update(progress: FireflyProgress) -> None:
        nonlocal bar
        if bar is None:
            bar = _terminal_bar(progress.iterations, "firefly", "it", leave=False)
        else:
            bar.update(1)
        bar.set_postfix(best=f"{progress.best:.4g}")

    def close() -> None:
        if bar is not None:
            bar.close()

    return update, close


def _plan_and_write(scene: Scene, out: Path, args: argparse.Namespace, paper: bool) -> int:
    from planning.io.outputs import plan_files, summary
    from planning.io.report import paper_rows, text_table
    from planning.io.trajectory_io import write_files
    from planning.planner import NoTrajectoryFoundError, plan

    planner = scene.planner
    overrides = {
        k: getattr(args, k)
        for k in ("seed", "fitness", "fireflies", "iterations")
        if getattr(args, k, None) is not None
    }
    if overrides:
        try:
            scene = dataclasses.replace(scene, planner=dataclasses.replace(planner, **overrides))
        except PlanningError as exc:
            raise _CommandError(EXIT_INVALID, str(exc)) from None
    update, close = _progress(sys.stdout.isatty() and not args.json)
    try:
        result = plan(scene, progress=update)
    except NoTrajectoryFoundError as exc:
        raise _CommandError(EXIT_NO_TRAJECTORY, str(exc)) from None
    except (PlanningError, ck.CprKinError) as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None
    finally:
        close()
    extras = {"plots": paper or args.plots, "html": paper or args.html}
    files = plan_files(result, paper=paper, timings=args.timings, **extras)
    try:
        outputs = write_files(out, files)
    except OSError as exc:
        raise _CommandError(EXIT_INVALID, f"cannot write to '{out}': {exc.strerror or exc}") from None
    if args.json:
        print(json.dumps({**summary(result), "outputs": [str(p) for p in outputs]}, indent=1))
    else:
        m = result.metrics
        print(
            f"{result.scene.name}: verified trajectory of {m.duration:.3f} s, certified clearance "
            f"{m.min_clearance:.4f} m (margin {scene.safety_margin} m), "
            f"node deviation {m.max_node_deviation:.3g}, "
            f"planned in {m.planning_time_s:.3f} s ({m.evaluations} evaluations)"
        )
        if paper:
            print(text_table(paper_rows(result)))
        print("wrote " + ", ".join(str(p) for p in outputs))
    return EXIT_OK


def _load(path: Path) -> Scene:
    from planning.io.scene_file import load_scene

    try:
        return load_scene(path)
    except PlanningError as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None


def _cmd_plan(args: argparse.Namespace) -> int:
    return _plan_and_write(_load(args.scene), args.out, args, paper=False)


def _cmd_paper(args: argparse.Namespace) -> int:
    from planning.io.scene_file import paper_scene_path

    return _plan_and_write(_load(paper_scene_path()), args.out, args, paper=True)


def _cmd_check(args: argparse.Namespace) -> int:
    from planning.io.trajectory_io import read_trajectory
    from planning.verification import verify_trajectory

    scene = _load(args.scene)
    try:
        document = read_trajectory(args.trajectory)
        robot = ck.load_cpr(scene.robot)
        world = ck.CollisionWorld(robot, scene.obstacles)
        q_start, q_goal = scene.start.configuration(robot), scene.goal.configuration(robot)
    except (PlanningError, ck.CprKinError) as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None
    if document.joint_names != robot.joint_names:
        raise _CommandError(
            EXIT_INVALID,
            f"trajectory joints {list(document.joint_names)} are not the robot's {list(robot.joint_names)}",
        )
    verification = verify_trajectory(
        world, document.trajectory, scene.safety_margin, scene.planner.verify_step_m, (q_start, q_goal)
    )
    check, problems = verification.check, list(verification.problems)
    verdict = {
        "status": "ok" if not problems else "failed",
        "certified_min_clearance_m": check.certified_min_m,
        "safety_margin_m": scene.safety_margin,
        "checks": len(check.times),
        "problems": problems,
    }
    if args.json:
        print(json.dumps(verdict, indent=1))
    elif problems:
        print(f"{args.trajectory}: FAILS {args.scene}:\n  " + "\n  ".join(problems))
    else:
        print(
            f"{args.trajectory}: verified against {args.scene}: "
            f"certified clearance {check.certified_min_m:.4f} m "
            f">= {scene.safety_margin} m over {len(check.times)} checks, joints within range and limits"
        )
    return EXIT_OK if not problems else EXIT_NO_TRAJECTORY


def _cmd_show(args: argparse.Namespace) -> int:
    from planning.io.scene_file import parse_scene
    from planning.io.trajectory_io import read_trajectory, write_files
    from planning.viz import artifacts

    try:
        document = read_trajectory(args.trajectory)
        scene = parse_scene(document.scene, source=f"{args.trajectory} (scene)")
        recorded = Path(document.robot)
        if not recorded.is_file():
            print(
                f"cpr-plan show: note: the recorded URDF '{recorded}' is not here; using the bundled CPR",
                file=sys.stderr,
            )
        robot = ck.load_cpr(recorded if recorded.is_file() else None)
    except (PlanningError, ck.CprKinError) as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None
    if args.html is not None:
        html = artifacts.viewer_html(
            robot,
            scene.obstacles,
            scene.safety_margin,
            document.trajectory,
            document.waypoints,
            args.collision,
        )
        try:
            written = write_files(args.html.parent, {args.html.name: html})
        except OSError as exc:
            raise _CommandError(EXIT_INVALID, f"cannot write '{args.html}': {exc.strerror or exc}") from None
        print(f"wrote {written[0]} (self-contained; open it in a browser)")
        return EXIT_OK
    from planning.viz.viewer import Viewer

    def stop(signum: int, _frame: object) -> None:
        raise KeyboardInterrupt(signal.Signals(signum).name)

    for signum in (signal.SIGINT, signal.SIGTERM):  # also when started with SIGINT ignored
        signal.signal(signum, stop)
    with Viewer(robot, scene.obstacles, scene.safety_margin) as viewer:
        viewer.show_geometry(visual=not args.collision, collision=args.collision)
        viewer.show_plan(document.trajectory, document.waypoints)
        viewer.animate(document.trajectory)
        print(f"meshcat viewer at {viewer.url}  (127.0.0.1 only; Ctrl-C to stop)", flush=True)
        try:
            while True:
                time.sleep(3600)
        except KeyboardInterrupt:
            print("viewer stopped", flush=True)
    return EXIT_OK


def _cmd_batch(args: argparse.Namespace) -> int:
    from planning import batch
    from planning.io.report import text_table
    from planning.io.trajectory_io import write_files

    try:
        paths = batch.scene_files(args.scenes)
    except PlanningError as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None
    bar: Any = None
    if sys.stdout.isatty() and not args.json:
        bar = _terminal_bar(len(paths), "scenes", "scene")
    try:
        tick = None if bar is None else (lambda _item: bar.update(1))
        items = batch.plan_batch(paths, args.out, args.workers, args.scheduler, tick)
    except PlanningError as exc:
        raise _CommandError(EXIT_INVALID, str(exc)) from None
    finally:
        if bar is not None:
            bar.close()
    write_files(args.out, {"summary.csv": batch.summary_csv(items)})
    failed = [i for i in items if i.status != "ok"]
    if args.json:
        print(
            json.dumps(
                {
                    "scenes": len(items),
                    "ok": len(items) - len(failed),
                    "items": [dataclasses.asdict(i) for i in items],
                },
                indent=1,
            )
        )
    else:
        rows = [
            (
                i.scene,
                i.status,
                str(i.exit_class),
                "-" if i.duration_s is None else f"{i.duration_s:.2f} s",
                "-" if i.min_clearance_m is None else f"{i.min_clearance_m:.3f} m",
                f"{i.planning_time_s:.2f} s",
            )
            for i in items
        ]
        print(text_table(rows, ("scene", "status", "exit", "duration", "clearance", "time")))
        print(f"{len(items) - len(failed)}/{len(items)} scenes planned; summary: {args.out / 'summary.csv'}")
        for item in failed:
            print(f"  {item.scene} (exit class {item.exit_class}): {item.message}")
    return EXIT_OK if not failed else EXIT_NO_TRAJECTORY


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cpr-plan", description="Collision-free, jerk-continuous trajectories for the CPR."
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def planning_options(sub: argparse.ArgumentParser) -> None:
        sub.add_argument(
            "--out", type=Path, required=True, help="output folder (trajectory.json, samples.csv, report.md)"
        )
        sub.add_argument("--seed", type=int, help="seed of the firefly search (default: the scene's)")
        sub.add_argument("--fitness", choices=("clearance", "paper"), help="fitness (default: the scene's)")
        sub.add_argument("--fireflies", type=int, help="population size (default: the scene's)")
        sub.add_argument("--iterations", type=int, help="firefly iterations (default: the scene's)")
        sub.add_argument("--json", action="store_true", help="print the summary as JSON")
        sub.add_argument(
            "--plots",
            action="store_true",
            help="also write joints.png, tcp_path.png, clearance.png, convergence.png",
        )
        sub.add_argument(
            "--html", action="store_true", help="also write viewer.html (meshcat, animated, self-contained)"
        )
        sub.add_argument(
            "--timings",
            action="store_true",
            help="record wall times in trajectory.json (then it is not reproducible byte for byte)",
        )

    sub = commands.add_parser(
        "plan",
        help="plan a scene file",
        description="Plan SCENE and write trajectory.json, samples.csv and report.md into --out.",
    )
    sub.add_argument("scene", type=Path, help="scene file (YAML)")
    planning_options(sub)
    sub.set_defaults(run=_cmd_plan)

    sub = commands.add_parser(
        "paper",
        help="plan the paper case",
        description="Plan the bundled paper scene and report it beside the paper's figures.",
    )
    planning_options(sub)
    sub.set_defaults(run=_cmd_paper)

    sub = commands.add_parser(
        "check",
        help="re-verify a trajectory file against a scene",
        description="Re-verify TRAJECTORY against SCENE: start and goal, certified clearance, "
        "joint ranges and limits.",
    )
    sub.add_argument("scene", type=Path, help="scene file (YAML)")
    sub.add_argument("trajectory", type=Path, help="trajectory file (cpr-trajectory/1 JSON)")
    sub.add_argument("--json", action="store_true", help="print the verdict as JSON")
    sub.set_defaults(run=_cmd_check)

    sub = commands.add_parser(
        "show",
        help="show a trajectory file in meshcat",
        description="Show TRAJECTORY with its scene in a live meshcat viewer (printing its URL), or write a "
        "self-contained HTML page with --html.",
    )
    sub.add_argument("trajectory", type=Path, help="trajectory file (cpr-trajectory/1 JSON)")
    sub.add_argument(
        "--html", type=Path, metavar="OUT.html", help="write a self-contained HTML page instead of serving"
    )
    sub.add_argument(
        "--collision", action="store_true", help="show the collision geometry instead of the visual one"
    )
    sub.set_defaults(run=_cmd_show)

    sub = commands.add_parser(
        "batch",
        help="plan every scene of a folder in parallel",
        description="Plan every *.yaml scene of SCENES_DIR in parallel (local processes, or a Dask cluster), "
        "writing DIR/<scene>/ outputs and DIR/summary.csv. A failing scene never stops the others. Exit 0 "
        "when every scene planned, 3 when any failed, 2 for an invalid folder or scheduler.",
    )
    sub.add_argument("scenes", type=Path, metavar="SCENES_DIR", help="folder of scene files")
    sub.add_argument("--out", type=Path, required=True, help="output folder")
    sub.add_argument("--workers", type=int, help="parallel tasks (default: all cores, or the cluster's)")
    sub.add_argument(
        "--scheduler", metavar="ADDRESS", help="dask.distributed scheduler, e.g. tcp://127.0.0.1:8786"
    )
    sub.add_argument("--json", action="store_true", help="print the results as JSON")
    sub.set_defaults(run=_cmd_batch)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``cpr-plan``; returns the exit code."""
    args = _parser().parse_args(argv)
    try:
        code: int = args.run(args)
    except _CommandError as failure:
        print(f"cpr-plan {args.command}: error: {failure}", file=sys.stderr)
        return failure.code
    except KeyboardInterrupt:
        print(f"cpr-plan {args.command}: interrupted", file=sys.stderr)
        return 130
    return code


if __name__ == "__main__":
    sys.exit(main())
