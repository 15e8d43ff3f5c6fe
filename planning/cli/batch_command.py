"""``cpr-plan batch``: plan every scene file of a folder in parallel."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

from planning.cli.failure import EXIT_INTERRUPTED, EXIT_INVALID, CommandError
from planning.cli.terminal import terminal_bar
from planning.errors import PlanningError


def cmd_batch(args: argparse.Namespace) -> int:
    """Plan every scene of a folder; ``summary.csv`` lists each scene's outcome.

    The exit code is the worst scene's class (0, 2, 3 or 4; see :mod:`planning.batch`), or
    130 when interrupted; ``summary.csv`` is written in every case, for the scenes done.
    """
    from planning import batch
    from planning.batch_pool import run_batch
    from planning.io.publish import FolderLock, write_file
    from planning.io.report import text_table

    out = Path(args.out) if str(args.out).strip() else args.out
    bar: Any = None
    try:
        paths = batch.scene_files(args.scenes)
        with FolderLock(out):
            if sys.stdout.isatty() and not args.json:
                bar = terminal_bar(len(paths), "scenes", "scene")
            tick = None if bar is None else (lambda _item: bar.update(1))
            run = run_batch(paths, Path(out), args.workers, args.scheduler, tick)
            if bar is not None:
                bar.close()
            write_file(Path(out) / "summary.csv", batch.summary_csv(run.items))
    except PlanningError as exc:
        raise CommandError(EXIT_INVALID, str(exc)) from None
    except OSError as exc:
        raise CommandError(EXIT_INVALID, f"cannot write to '{out}': {exc.strerror or exc}") from None
    items = run.items
    failed = [i for i in items if i.status != "ok"]
    if args.json:
        items_json = [dataclasses.asdict(i) for i in items]
        summary = {
            "scenes": len(paths),
            "done": len(items),
            "ok": len(items) - len(failed),
            "items": items_json,
        }
        print(json.dumps({**summary, "interrupted": run.interrupted}, indent=1))
    else:
        rows = []
        for item in items:
            record = item.record or {}
            duration, clearance = record.get("duration"), record.get("min_clearance")
            rows.append(
                (
                    item.scene,
                    item.status,
                    str(item.exit_class),
                    "-" if duration is None else f"{duration:.2f} s",
                    "-" if clearance is None else f"{clearance:.3f} m",
                    f"{item.task_time_s:.2f} s",
                )
            )
        print(text_table(rows, ("scene", "status", "exit", "duration", "clearance", "time")))
        planned = f"{len(items) - len(failed)}/{len(paths)} scenes planned"
        print(f"{planned}; summary: {Path(out) / 'summary.csv'}")
        for item in failed:
            print(f"  {item.scene} (exit class {item.exit_class}): {item.message}")
    if run.interrupted:
        print(f"cpr-plan batch: interrupted after {len(items)} of {len(paths)} scenes", file=sys.stderr)
        return EXIT_INTERRUPTED
    return max((i.exit_class for i in items), default=0)
