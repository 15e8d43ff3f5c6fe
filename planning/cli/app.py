"""The ``cpr-plan`` argument parser and entry point."""

from __future__ import annotations

import argparse
import os
import signal
import sys
from collections.abc import Sequence
from pathlib import Path

from planning.cli.batch_command import cmd_batch
from planning.cli.failure import EXIT_INTERNAL, EXIT_INTERRUPTED, CommandError
from planning.cli.file_commands import cmd_check, cmd_show
from planning.cli.plan_commands import cmd_paper, cmd_plan


def build_parser() -> argparse.ArgumentParser:
    """The parser of every command; each sets `run`, the function that runs it."""
    parser = argparse.ArgumentParser(
        prog="cpr-plan", description="Collision-free, jerk-continuous trajectories for the CPR."
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
        "joint ranges and limits.",
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
    sub.set_defaults(run=cmd_show)

    sub = commands.add_parser(
        "batch",
        help="plan every scene of a folder in parallel",
        description="Plan every *.yaml scene of SCENES_DIR in parallel (local processes, or a Dask cluster), "
        "writing DIR/<scene>/ outputs and DIR/summary.csv. A failing scene never stops the others. Exit 0 "
        "when every scene planned, 3 when any failed, 2 for an invalid folder or scheduler.",
    )
    sub.add_argument("scenes", type=Path, metavar="SCENES_DIR", help="folder of scene files")
    sub.add_argument("--out", required=True, help="output folder (a subfolder per scene, and summary.csv)")
    sub.add_argument("--workers", type=int, help="parallel tasks (default: all cores, or the cluster's)")
    sub.add_argument(
        "--scheduler", metavar="ADDRESS", help="dask.distributed scheduler, e.g. tcp://127.0.0.1:8786"
    )
    sub.add_argument("--json", action="store_true", help="print the results as JSON")
    sub.set_defaults(run=cmd_batch)
    return parser


MAX_ERROR_CHARS = 300
"""Longest error line the CLI prints (a hostile input must not flood the terminal)."""


def _one_line(text: str) -> str:
    text = " ".join(text.split())
    return text if len(text) <= MAX_ERROR_CHARS else text[: MAX_ERROR_CHARS - 3] + "..."


def _stop(signum: int, _frame: object) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``cpr-plan``; returns the exit code.

    ``SIGINT`` and ``SIGTERM`` stop any command cleanly (exit 130; nothing half-written),
    also when the shell started it with ``SIGINT`` ignored (``cpr-plan batch ... &``). An
    unexpected exception is a bug: one line and exit 4; ``CPR_PLAN_TRACEBACK=1`` shows it whole.
    """
    args = build_parser().parse_args(argv)
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _stop)
    try:
        code: int = args.run(args)
    except CommandError as failure:
        print(_one_line(f"cpr-plan {args.command}: error: {failure}"), file=sys.stderr)
        return failure.code
    except KeyboardInterrupt:
        print(f"cpr-plan {args.command}: interrupted; nothing written", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:
        if os.environ.get("CPR_PLAN_TRACEBACK"):
            raise
        bug = f"cpr-plan {args.command}: internal error (a bug; please report it with the input)"
        print(_one_line(f"{bug}: {type(exc).__name__}: {exc}"), file=sys.stderr)
        return EXIT_INTERNAL
    return code
