"""``cpr-plan plan`` and ``cpr-plan paper``: plan a scene and write its files."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from cpr_kin.common.names import escaped
from planning.cli.signals import checkpoint
from planning.cli.terminal import firefly_progress
from planning.io import json_layout
from planning.outcome import EXIT_OK, Interrupted, interruption

if TYPE_CHECKING:
    from collections.abc import Callable

    from planning.io.publish import OutputFolder
    from planning.io.scene_file import SceneFile
    from planning.pipeline.scene import Scene
    from planning.search.firefly import FireflyProgress

OVERRIDES = ("seed", "fitness", "fireflies", "iterations", "time_limit_s")
"""Planner settings the command line may change, by their scene-file keys."""


def load(path: Path) -> SceneFile:
    """The scene file at ``path``, its task too (a :class:`~planning.errors.SceneError` names the fault)."""
    from planning.io.scene_file import load_scene_file

    return load_scene_file(path)


def _checked(update: Callable[[FireflyProgress], None] | None) -> Callable[[FireflyProgress], None]:
    """The search's progress callback, with a :func:`~planning.cli.signals.checkpoint` each iteration."""

    def progress(state: FireflyProgress) -> None:
        checkpoint()  # a signal something swallowed stops the search at its next iteration
        if update is not None:
            update(state)

    return progress


def _with_overrides(scene: Scene, args: argparse.Namespace) -> Scene:
    """``scene`` with the planner settings the command line changes."""
    from planning.pipeline.settings import PAPER_SEARCH

    overrides = {k: getattr(args, k) for k in OVERRIDES if getattr(args, k, None) is not None}
    if getattr(args, "paper_search", False):
        overrides = {**PAPER_SEARCH, **overrides}  # a --fireflies or --iterations given still wins
    return scene.with_planner(**overrides) if overrides else scene


def _plan_and_write(read: SceneFile, out: str, args: argparse.Namespace, paper: bool) -> int:
    from planning.io.outputs import plan_files
    from planning.io.publish import OutputFolder
    from planning.io.report import paper_rows, summary, summary_line, text_table
    from planning.pipeline.planner import plan

    scene = _with_overrides(read.scene, args)
    update, close = firefly_progress(sys.stdout.isatty() and not args.json)
    with OutputFolder(out) as folder:  # locked from here: a second writer is refused at once
        try:
            if read.task:
                return _task_planned_and_written(scene, read, folder, args, update, close)
            result = plan(scene, progress=_checked(update))
            close()
            files = plan_files(result, paper=paper, timings=args.timings)
            if paper or args.plots or args.html:
                from planning.viz.artifacts import drawn_files

                files |= drawn_files(result, plots=paper or args.plots, page=paper or args.html)
            checkpoint()  # a signal something swallowed still stops the command before it writes
            outputs = folder.publish(files)
            if args.json:
                print(json_layout.dumps({**summary(result), "outputs": [str(p) for p in outputs]}))
            else:
                print(summary_line(result))
                if paper:
                    print(text_table(paper_rows(result)))
                print(escaped("wrote " + ", ".join(str(p) for p in outputs)))
        except BaseException as exc:
            if folder.published and interruption(exc) is not None:
                raise Interrupted(f"interrupted; the new set in '{out}' is complete") from None
            raise
        finally:
            close()
    return EXIT_OK


def _task_planned_and_written(
    scene: Scene,
    read: SceneFile,
    folder: OutputFolder,
    args: argparse.Namespace,
    update: Callable[[FireflyProgress], None] | None,
    close: Callable[[], None],
) -> int:
    """Plan the scene file's task and publish its files (:mod:`planning.io.task_outputs`)."""
    from planning.io.task_outputs import task_files, task_summary, task_summary_line
    from planning.task import plan_task

    began = time.perf_counter()
    task = plan_task(scene, read.task, progress=_checked(update))
    elapsed = time.perf_counter() - began
    close()
    task = task.verified()
    files = task_files(task, elapsed if args.timings else None)
    if args.plots or args.html:
        from planning.viz.artifacts import task_drawn_files

        files |= task_drawn_files(task, plots=args.plots, page=args.html)
    checkpoint()
    outputs = folder.publish(files)
    if args.json:
        print(json_layout.dumps({**task_summary(task, elapsed), "outputs": [str(p) for p in outputs]}))
    else:
        print(task_summary_line(task, elapsed))
        print(escaped("wrote " + ", ".join(str(p) for p in outputs)))
    return EXIT_OK


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan a scene file."""
    return _plan_and_write(load(args.scene), args.out, args, paper=False)


def cmd_paper(args: argparse.Namespace) -> int:
    """Plan the bundled paper scene, beside the paper's figures."""
    from planning.io.bundled import paper_scene_path

    return _plan_and_write(load(paper_scene_path()), args.out, args, paper=True)
