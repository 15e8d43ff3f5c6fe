"""The ``cpr-plan`` argument parser and entry point."""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from cpr_kin.common.names import one_line
from planning.cli.arguments import add_package_dirs, integer_at_least
from planning.cli.batch_command import cmd_batch
from planning.cli.file_commands import EXPORTERS, cmd_check, cmd_export, cmd_show
from planning.cli.moveit_command import cmd_import_moveit
from planning.cli.plan_commands import cmd_paper, cmd_plan
from planning.cli.process import end_process, start_process
from planning.cli.robot_command import cmd_robot_info
from planning.cli.signals import interrupts
from planning.notices import library_notices
from planning.outcome import EXIT_INTERRUPTED, Interrupted, classify


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command; each sets `run`, the function that runs it."""
    parser = argparse.ArgumentParser(
        prog="cpr-plan",
        description="Collision-free, jerk-continuous trajectories for any serial arm (the CPR by default)",
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    def planning_options(sub: argparse.ArgumentParser) -> None:
        sub.add_argument(
            "--out",
            required=True,
            help="output folder, new, empty or a previous plan's (trajectory.json, samples.csv, report.md)",
        )
        sub.add_argument("--seed", type=int, help="seed of the firefly search (default: the scene's)")
        sub.add_argument("--fitness", choices=("clearance", "paper"), help="fitness (default: the scene's)")
        sub.add_argument("--fireflies", type=int, help="population size (default: the scene's)")
        sub.add_argument("--iterations", type=int, help="firefly iterations (default: the scene's)")
        sub.add_argument(
            "--time-limit",
            dest="time_limit_s",
            type=float,
            metavar="SECONDS",
            help="stop the search after this many seconds and keep what it found (default: the scene's)",
        )
        sub.add_argument(
            "--paper-search",
            action="store_true",
            help="search with the paper's firefly (n = 50, 50 iterations, alpha 1, beta0 0.5, every "
            "iteration) from a random population, not the planner's seeded search with early stop",
        )
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
    sub.set_defaults(run=cmd_plan)

    sub = commands.add_parser(
        "paper",
        help="plan the paper case",
        description="Plan the bundled paper scene and report it beside the paper's figures.",
    )
    planning_options(sub)
    sub.set_defaults(run=cmd_paper)

    sub = commands.add_parser(
        "check",
        help="re-verify a trajectory file against a scene",
        description="Re-verify TRAJECTORY against SCENE: start and goal, certified clearance, "
        "joint ranges and limits, joint torques (with the scene's payload) within the effort limits.",
    )
    sub.add_argument("scene", type=Path, help="scene file (YAML)")
    sub.add_argument("trajectory", type=Path, help="trajectory file (cpr-trajectory/1 JSON)")
    sub.add_argument("--json", action="store_true", help="print the verdict as JSON")
    sub.set_defaults(run=cmd_check)

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
    sub.add_argument(
        "--urdf",
        type=Path,
        help="the robot's URDF when the one the file records is not here, or a name: 'cpr' (the bundled "
        "CPR), an example-robot-data arm's (panda, ur5, ...)",
    )
    sub.set_defaults(run=cmd_show)

    sub = commands.add_parser(
        "import-moveit",
        help="convert a MoveIt planning scene and request into a scene file",
        description="Convert a MoveIt PlanningScene and MotionPlanRequest (YAML) into a scene file that "
        "'cpr-plan plan' runs; what the conversion cannot represent is refused, naming it (docs/formats.md).",
    )
    sub.add_argument("scene", type=Path, metavar="PLANNING_SCENE.yaml", help="moveit_msgs/PlanningScene")
    sub.add_argument("request", type=Path, metavar="REQUEST.yaml", help="moveit_msgs/MotionPlanRequest")
    sub.add_argument("--urdf", type=Path, required=True, help="the robot's URDF")
    sub.add_argument("--srdf", type=Path, help="its SRDF (planning groups, disabled collision pairs)")
    add_package_dirs(sub)
    sub.add_argument(
        "--limits", type=Path, help="acceleration and jerk limits file (default: found, or defaults)"
    )
    sub.add_argument(
        "--safety-margin",
        type=float,
        default=0.0,
        metavar="M",
        help="clearance to obstacles [m] (default 0: contact-free, as MoveIt)",
    )
    sub.add_argument(
        "--self-margin",
        type=float,
        default=0.0,
        metavar="M",
        help="clearance between robot links [m] (default 0)",
    )
    sub.add_argument("--out", type=Path, required=True, metavar="SCENE.yaml", help="scene file to write")
    sub.set_defaults(run=cmd_import_moveit)

    sub = commands.add_parser(
        "export",
        help="write a trajectory file in another format",
        description="Write TRAJECTORY in another format: "
        + "; ".join(f"{name}: {what}" for name, what in EXPORTERS.items())
        + ".",
    )
    sub.add_argument("trajectory", type=Path, help="trajectory file (cpr-trajectory/1 JSON)")
    sub.add_argument("--format", required=True, choices=sorted(EXPORTERS), help="the format to write")
    sub.add_argument(
        "--rate", type=float, default=100.0, metavar="HZ", help="points per second (default 100)"
    )
    sub.add_argument(
        "--out", type=Path, required=True, metavar="FILE", help="file to write (.yaml, .yml, .json)"
    )
    sub.set_defaults(run=cmd_export)

    sub = commands.add_parser(
        "robot-info",
        help="show what the planner makes of a robot",
        description="Load ROBOT as a scene's robot: would, and print its files, planned and held joints with "
        "their limits, tool frame, collision shapes with how far each reaches beyond its link's mesh "
        "(a convex hull fills a concave link's hollows), and its self-collision pairs.",
    )
    sub.add_argument(
        "robot",
        metavar="ROBOT",
        help="a URDF file, an example-robot-data arm's name (panda, ur5, ...), 'cpr' (the bundled CPR), "
        "or a scene file (.yaml: the robot it names)",
    )
    sub.add_argument(
        "--tcp",
        metavar="FRAME",
        help="its tool frame: the joints from the root to it are planned (a scene's tcp)",
    )
    sub.add_argument(
        "--srdf", type=Path, metavar="FILE", help="its SRDF (default: found by name beside the URDF)"
    )
    add_package_dirs(sub)
    sub.add_argument("--json", action="store_true", help="print the report as JSON")
    sub.set_defaults(run=cmd_robot_info)

    sub = commands.add_parser(
        "batch",
        help="plan every scene of a folder in parallel",
        description="Plan every *.yaml scene of SCENES_DIR in parallel (local processes, or a Dask cluster), "
        "writing DIR/<scene>/ outputs and DIR/summary.csv. A failing scene never stops the others. Exits "
        "with the worst scene's code (0 all planned, 2 invalid, 3 no trajectory, 4 a bug or a crashed "
        "worker), 2 for an invalid folder or scheduler, 130 when interrupted.",
    )
    sub.add_argument("scenes", type=Path, metavar="SCENES_DIR", help="folder of scene files")
    sub.add_argument("--out", required=True, help="output folder (a subfolder per scene, and summary.csv)")
    sub.add_argument(
        "--workers",
        type=integer_at_least(1),
        help="parallel scenes on this machine (default: all cores; with --scheduler: the cluster's threads)",
    )
    sub.add_argument(
        "--scheduler", metavar="ADDRESS", help="dask.distributed scheduler, e.g. tcp://127.0.0.1:8786"
    )
    sub.add_argument("--json", action="store_true", help="print the results as JSON")
    sub.set_defaults(run=cmd_batch)
    return parser


def main(argv: Sequence[str] | None = None, *, restore_signals: bool = True) -> int:
    """Entry point of ``cpr-plan``; returns the exit code.

    Every failure is classified once (:func:`planning.outcome.classify`): exit 2 for invalid
    input, 3 for no trajectory, 130 when ``SIGINT`` or ``SIGTERM`` stopped the command (also
    inside compiled code, and when a shell started it with ``SIGINT`` ignored), 4 for an
    unexpected exception, a bug (``CPR_PLAN_TRACEBACK=1`` shows it whole). One line on
    stderr, never a traceback; on a terminal, a first run's compilation is said there too
    (:func:`library_notices`). ``restore_signals=False`` (the installed command) ignores a
    signal that comes once the command is over.
    """
    args = build_parser().parse_args(argv)
    label = f"cpr-plan {args.command}"
    with interrupts(restore=restore_signals) as signalled, library_notices(label):
        try:
            code: int = args.run(args)
        except SystemExit:
            raise
        except BaseException as exc:
            outcome = classify(exc)
            if outcome.status == "interrupted" or signalled():
                said = str(exc) if isinstance(exc, Interrupted) else "interrupted; nothing written"
                print(one_line(f"{label}: {said}"), file=sys.stderr)
                return EXIT_INTERRUPTED
            if outcome.status == "error":
                if os.environ.get("CPR_PLAN_TRACEBACK"):
                    raise
                bug = f"{label}: internal error (a bug; please report it with the input)"
                print(one_line(f"{bug}: {outcome.message}"), file=sys.stderr)
            else:
                print(one_line(f"{label}: error: {outcome.message}"), file=sys.stderr)
            return outcome.exit_code
    return code


def console_main() -> NoReturn:
    """The installed ``cpr-plan`` (and ``python -m planning.cli``): :func:`main`, late signals ignored.

    The process runs this one command and ends (:mod:`planning.cli.process`).
    """
    start_process()
    end_process(main(restore_signals=False))
