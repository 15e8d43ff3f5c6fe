"""``cpr-plan batch``: plan every scene file of a folder in parallel."""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path
from typing import Any

from cpr_kin.common.names import escaped
from planning.cli.terminal import terminal_bar
from planning.io import json_layout
from planning.outcome import EXIT_INTERRUPTED


def cmd_batch(args: argparse.Namespace) -> int:
    """Plan every scene of a folder; ``summary.csv`` lists each scene's outcome.

    Every path (the scene folder, ``--out``) is made absolute here, before any work is sent:
    a worker of a Dask cluster runs in a folder of its own. The exit code is the worst
    scene's (0, 2, 3 or 4; :mod:`planning.outcome`), or 130 when interrupted;
    ``summary.csv`` is written in every case, for the scenes done.
    """
    from planning.batch import check_scheduler, check_workers, run_batch, scene_files, summary_csv
    from planning.io.publish import FolderLock, write_file
    from planning.io.report import text_table

    if args.scheduler is not None:
        check_scheduler(args.scheduler)
    check_workers(args.workers, args.scheduler)
    paths = scene_files(args.scenes)
    with FolderLock(args.out) as lock:
        out = lock.target  # absolute: the workers write there, wherever they run
        bar: Any = None
        if sys.stdout.isatty() and not args.json:
            bar = terminal_bar(len(paths), "scenes", "scene")
        tick = None if bar is None else (lambda _item: bar.update(1))
        run = run_batch(paths, out, args.workers, args.scheduler, tick)
        if bar is not None:
            bar.close()
        write_file(out / "summary.csv", summary_csv(run.items))
    items = run.items
    failed = [i for i in items if i.status != "ok"]
    if args.json:
        summary = {"scenes": len(paths), "done": len(items), "ok": len(items) - len(failed)}
        items_json = [dataclasses.asdict(i) for i in items]
        print(json_layout.dumps({**summary, "items": items_json, "interrupted": run.interrupted}))
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
        print(escaped(f"{planned}; summary: {Path(args.out) / 'summary.csv'}"))
        for item in failed:
            print(f"  {item.scene} (exit class {item.exit_class}): {item.message}")
    if run.interrupted:
        print(f"cpr-plan batch: interrupted after {len(items)} of {len(paths)} scenes", file=sys.stderr)
        return EXIT_INTERRUPTED
    return max((i.exit_class for i in items), default=0)
