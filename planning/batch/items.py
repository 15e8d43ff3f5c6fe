"""Planning many scene files: one isolated task per scene, and the summary of their outcomes.

:func:`plan_scene_file` plans one scene and publishes its outputs into ``out/<scene stem>/``;
it never raises: every outcome, an unexpected exception included, becomes a
:class:`BatchItem`. :mod:`planning.batch.pool` runs the tasks in parallel and turns a worker
that dies (a crash in a native library) into the row of the scene that killed it.
:func:`summary_csv` writes one row per scene. A scene file that holds a task (moves, lines,
waits, attach and detach: :mod:`planning.task`) is planned as ``cpr-plan plan`` plans it; its
row has the task's duration, clearance and planning time (no ``t_sol``, fitness or evaluations).

Statuses and their exit classes are those of :mod:`planning.outcome` (the batch exits with
the worst one):

- ``ok`` (0): planned, verified, written;
- ``invalid`` (2): bad input (scene file, robot, settings) or an unwritable output folder;
- ``no_trajectory`` (3): valid input, but no verified trajectory found;
- ``error`` (4): an unexpected exception while planning (a bug: please report it);
- ``crashed`` (4): the worker process died while planning this scene.

A task gets absolute paths (:func:`scene_files`, and the caller's output folder): a worker of
a Dask cluster runs in a folder of its own, and the scene's own relative paths (``robot:``,
meshes) are resolved against the scene file.
"""

from __future__ import annotations

import contextlib
import csv
import io
import time
from collections.abc import Iterator
from contextlib import AbstractContextManager
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import cpr_kin as ck  # lazy (lazy_loader): its modules load in the workers, where they are used
from cpr_kin.common.names import escaped, one_line, repeated
from cpr_kin.common.user_files import is_yaml_name
from planning.errors import PlanningError
from planning.notices import library_notices
from planning.outcome import STATUS_EXIT, classify

if TYPE_CHECKING:  # the scene reader is imported in the workers, where scenes are planned
    from planning.io.scene_file import SceneFile

RECORD_FIELDS = ("duration", "min_clearance", "t_sol", "fitness", "evaluations", "planning_time_s")
"""The plan record's fields (:func:`planning.io.report.plan_record`) that ``summary.csv`` shows."""
SUMMARY_FIELDS = ("scene", "status", "exit_class", *RECORD_FIELDS, "task_time_s", "message")


@dataclass(frozen=True)
class BatchItem:
    """The outcome of one scene.

    Attributes:
        scene: the scene file's stem (its output folder's name).
        status: ``ok``, ``invalid``, ``no_trajectory``, ``error`` or ``crashed`` (see the
            module docstring).
        exit_class: the status's exit code, :data:`STATUS_EXIT`.
        message: what went wrong, empty when ok (one line, at most
            :data:`~cpr_kin.common.names.MAX_LINE_CHARS`).
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

    @classmethod
    def failed(cls, scene: str, status: str, message: str, started: float | None = None) -> BatchItem:
        """A failed scene's row; ``started`` is the task's ``time.perf_counter()`` at its start."""
        elapsed = 0.0 if started is None else time.perf_counter() - started
        return cls(escaped(scene), status, STATUS_EXIT[status], one_line(message), None, elapsed)


class Gate(Protocol):
    """What lets a task publish its files (a cluster's :class:`~planning.batch.cluster.PublishGate`)."""

    def __call__(self, item: BatchItem) -> AbstractContextManager[bool]:
        """A context that yields whether the scene of ``item`` may publish now."""
        ...


@contextlib.contextmanager
def _open(item: BatchItem) -> Iterator[bool]:
    """The gate of a local batch: always open (an interrupt kills the local workers)."""
    yield True


def plan_scene_file(path: Path, out: Path, threads: int | None = 1, gate: Gate = _open) -> BatchItem:
    """Plan one scene file (one motion, or a task) and publish its outputs into ``out``; never raises.

    ``threads = 1`` by default: the batch runs scenes in parallel, not the checks of one.
    The files are published within ``gate``; a closed gate (an interrupted cluster batch)
    makes the row ``interrupted`` and writes nothing. It imports the planner itself, in the
    worker: the process that dispatches the scenes never needs it. A worker whose stderr is a
    terminal (a local batch run from one) says there that it compiles the kernels
    (:func:`~planning.notices.library_notices`).
    """
    from planning.io.publish import OutputFolder
    from planning.io.scene_file import load_scene_file

    started = time.perf_counter()
    name = path.stem
    try:
        read = load_scene_file(path)
        with OutputFolder(out) as folder, library_notices("cpr-plan batch"):
            robot = ck.shared_robot(read.scene.robot_spec())  # one per worker thread
            record, files = (
                _task_outputs(read, robot, threads) if read.task else _plan_outputs(read, robot, threads)
            )
            item = BatchItem(escaped(name), "ok", 0, record=record, task_time_s=time.perf_counter() - started)
            with gate(item) as open_:
                if not open_:
                    stopped = "the batch was interrupted before this scene's files were written"
                    return BatchItem.failed(name, "interrupted", stopped, started)
                folder.publish(files)
    except Exception as exc:  # every outcome is a row (a bug's too): the batch goes on
        outcome = classify(exc)
        return BatchItem.failed(name, outcome.status, outcome.message, started)
    return item


Outputs = tuple[dict[str, Any], dict[str, str | bytes]]
"""A planned scene's record (its summary row's fields) and its files by name."""


def _plan_outputs(read: SceneFile, robot: ck.Robot, threads: int | None) -> Outputs:
    """The plan of a scene of one motion: its record and files (``cpr-plan plan``'s)."""
    from planning.io.outputs import plan_files
    from planning.io.report import plan_record
    from planning.pipeline.planner import plan

    result = plan(read.scene, robot, threads=threads)
    return plan_record(result), plan_files(result)


def _task_outputs(read: SceneFile, robot: ck.Robot, threads: int | None) -> Outputs:
    """The plan of a task: its metrics as the record and its files (``cpr-plan plan``'s for a task)."""
    from planning.io.task_outputs import task_files, task_metrics
    from planning.task import plan_task

    began = time.perf_counter()
    task = plan_task(read.scene, read.task, robot, threads=threads).verified()
    return task_metrics(task, time.perf_counter() - began), task_files(task)


def finished_items(futures: dict[Any, int]) -> Iterator[tuple[int, BatchItem]]:
    """``(index, item)`` of the futures (``{future: index}``) that completed with an item."""
    for future, index in futures.items():
        try:
            item = future.result(timeout=1)
        except BaseException:  # cancelled, failed or still running: not a finished scene
            continue
        yield index, item


def scene_files(folder: Path) -> list[Path]:
    """The scene files (``*.yaml``, ``*.yml``, any case) of ``folder``, sorted by name, absolute."""
    folder = folder.absolute()
    if not folder.is_dir():
        raise PlanningError(f"scene folder '{folder}' does not exist or is not a folder")
    files = sorted(p for p in folder.iterdir() if is_yaml_name(p) and p.is_file())
    if not files:
        raise PlanningError(f"scene folder '{folder}' holds no .yaml scene files")
    stems = [p.stem for p in files]
    clashing = repeated(stems)
    if clashing:
        raise PlanningError(f"scene files {clashing[:5]} share a stem (and so an output folder); rename one")
    return files


def summary_csv(items: list[BatchItem]) -> str:
    """``summary.csv``: one row per scene: its status, the record's :data:`RECORD_FIELDS`, its message."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=SUMMARY_FIELDS, lineterminator="\n")
    writer.writeheader()
    for item in items:
        record = item.record or {}
        row = {k: v for k, v in asdict(item).items() if k != "record"}
        writer.writerow({**row, **{k: record.get(k, "") for k in RECORD_FIELDS}})
    return buffer.getvalue()
