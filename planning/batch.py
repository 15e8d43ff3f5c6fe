"""Planning many scenes in parallel: joblib processes locally, or a Dask cluster.

:func:`plan_batch` plans every scene file in its own task; each writes its outputs into
``out/<scene file stem>/`` and returns a :class:`BatchItem`, so one failing scene never
stops the others. Parallelism is joblib's: local processes (``loky``) by default, or a
``dask.distributed`` cluster through joblib's Dask backend when a scheduler address is
given. Results come back in the order of the scene files whatever the backend.
"""

from __future__ import annotations

import csv
import io
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import asdict, dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import joblib

import cpr_kin as ck  # lazy (lazy_loader): its modules load in the workers, where they are used
from planning.errors import NoSolutionError, PlanningError

STATUS_EXIT = {"ok": 0, "invalid": 2, "no_trajectory": 3}
RECORD_FIELDS = ("duration", "min_clearance", "t_sol", "fitness", "evaluations", "planning_time_s")
"""The plan record's fields (:func:`planning.io.report.plan_record`) that ``summary.csv`` shows."""
SUMMARY_FIELDS = ("scene", "status", "exit_class", *RECORD_FIELDS, "task_time_s", "message")


@dataclass(frozen=True)
class BatchItem:
    """The outcome of one scene.

    Attributes:
        scene: the scene file's stem (its output folder's name).
        status: ``ok``, ``invalid`` (bad scene) or ``no_trajectory``.
        exit_class: the exit code ``cpr-plan plan`` would give: 0, 2 or 3.
        message: the error for a failed scene, empty otherwise.
        record: the plan's record (:func:`planning.io.report.plan_record`, the trajectory
            file's metrics), ``None`` for a failed scene.
        task_time_s: wall time of the task: loading, planning and writing [s].
    """

    scene: str
    status: str
    exit_class: int
    message: str = ""
    record: dict[str, Any] | None = None
    task_time_s: float = 0.0


@lru_cache(maxsize=8)
def _robot(urdf: Path | None) -> ck.Robot:
    """The robot, loaded once per worker process and URDF."""
    return ck.load_cpr(urdf)


def plan_scene_file(path: Path, out: Path, threads: int | None = 1) -> BatchItem:
    """Plan one scene file and write its outputs into ``out``; never raises on bad input.

    ``threads = 1`` by default: the batch runs scenes in parallel, not the checks of one.
    It imports the planner itself, in the worker: the process that dispatches the scenes
    never needs it.
    """
    from planning.io.outputs import plan_files
    from planning.io.report import plan_record
    from planning.io.scene_file import load_scene
    from planning.io.trajectory_io import write_files
    from planning.planner import plan

    started = time.perf_counter()
    name = path.stem
    try:
        scene = load_scene(path)
        result = plan(scene, _robot(scene.robot), threads=threads)
    except NoSolutionError as exc:
        return BatchItem(name, "no_trajectory", 3, str(exc), task_time_s=time.perf_counter() - started)
    except (PlanningError, ck.CprKinError) as exc:
        return BatchItem(name, "invalid", 2, str(exc), task_time_s=time.perf_counter() - started)
    try:
        write_files(out, plan_files(result))
    except OSError as exc:
        return BatchItem(
            name, "invalid", 2, f"cannot write '{out}': {exc}", task_time_s=time.perf_counter() - started
        )
    return BatchItem(name, "ok", 0, record=plan_record(result), task_time_s=time.perf_counter() - started)


def scene_files(folder: Path) -> list[Path]:
    """The scene files (``*.yaml``, ``*.yml``) of ``folder``, sorted by name."""
    if not folder.is_dir():
        raise PlanningError(f"scene folder '{folder}' does not exist or is not a folder")
    files = sorted(p for p in folder.iterdir() if p.suffix in (".yaml", ".yml") and p.is_file())
    if not files:
        raise PlanningError(f"scene folder '{folder}' holds no .yaml scene files")
    stems = [p.stem for p in files]
    clashing = sorted({s for s in stems if stems.count(s) > 1})
    if clashing:
        raise PlanningError(f"scene files {clashing} share a stem (and so an output folder); rename one")
    return files


def plan_batch(
    paths: Sequence[Path],
    out: Path,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[BatchItem], None] | None = None,
) -> list[BatchItem]:
    """Plan every scene file in parallel; outputs go to ``out/<stem>/``.

    Args:
        paths: scene files.
        out: output folder.
        workers: parallel tasks (default: every core locally; the cluster's size on Dask).
        scheduler: address of a ``dask.distributed`` scheduler, e.g. ``tcp://127.0.0.1:8786``.
        progress: called with each item as it completes.
    """
    tasks = (joblib.delayed(plan_scene_file)(path, out / path.stem) for path in paths)

    def run(backend_jobs: int) -> Iterator[BatchItem]:
        runner = joblib.Parallel(n_jobs=backend_jobs, return_as="generator")
        yield from runner(tasks)

    items: list[BatchItem] = []
    if scheduler is None:
        results = run(workers or -1)
        for item in results:
            items.append(item)
            if progress is not None:
                progress(item)
        return items
    try:
        from dask.distributed import Client
    except ImportError:
        raise PlanningError(
            "a Dask scheduler needs dask.distributed: pip install 'dask[distributed]'"
        ) from None
    try:
        client = Client(scheduler, timeout=10)  # type: ignore[no-untyped-call]
    except (OSError, TimeoutError) as exc:
        raise PlanningError(f"cannot reach the Dask scheduler at '{scheduler}': {exc}") from None
    with client, joblib.parallel_config(backend="dask"):
        for item in run(workers or -1):
            items.append(item)
            if progress is not None:
                progress(item)
    return items


def summary_csv(items: Sequence[BatchItem]) -> str:
    """``summary.csv``: one row per scene: its status, the record's :data:`RECORD_FIELDS`, its message."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=SUMMARY_FIELDS, lineterminator="\n")
    writer.writeheader()
    for item in items:
        record = item.record or {}
        row = {k: v for k, v in asdict(item).items() if k != "record"}
        writer.writerow({**row, **{k: record.get(k, "") for k in RECORD_FIELDS}})
    return buffer.getvalue()
