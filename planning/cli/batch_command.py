"""``cpr-plan batch``: plan every scene file of a folder in parallel."""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from typing import Any

from planning.cli.failure import EXIT_INVALID, EXIT_NO_TRAJECTORY, EXIT_OK, CommandError
from planning.cli.terminal import terminal_bar
from planning.errors import PlanningError


def cmd_batch(args: argparse.Namespace) -> int:
    """Plan every scene of a folder; ``summary.csv`` lists each scene's outcome."""
    from planning import batch
    from planning.io.report import text_table
    from planning.io.trajectory_io import write_files

    try:
        paths = batch.scene_files(args.scenes)
    except PlanningError as exc:
        raise CommandError(EXIT_INVALID, str(exc)) from None
    bar: Any = None
    if sys.stdout.isatty() and not args.json:
        bar = terminal_bar(len(paths), "scenes", "scene")
    try:
        tick = None if bar is None else (lambda _item: bar.update(1))
        items = batch.plan_batch(paths, args.out, args.workers, args.scheduler, tick)
    except PlanningError as exc:
        raise CommandError(EXIT_INVALID, str(exc)) from None
    finally:
        if bar is not None:
            bar.close()
    write_files(args.out, {"summary.csv": batch.summary_csv(items)})
    failed = [i for i in items if i.status != "ok"]
    if args.json:
        items_json = [dataclasses.asdict(i) for i in items]
        print(
            json.dumps({"scenes": len(items), "ok": len(items) - len(failed), "items": items_json}, indent=1)
        )
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
        print(f"{len(items) - len(failed)}/{len(items)} scenes planned; summary: {args.out / 'summary.csv'}")
        for item in failed:
            print(f"  {item.scene} (exit class {item.exit_class}): {item.message}")
    return EXIT_OK if not failed else EXIT_NO_TRAJECTORY
