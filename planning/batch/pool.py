"""Running the scene tasks of a batch in parallel, so that nothing one scene does sinks the rest.

Locally, ``loky``'s process pool runs :func:`planning.batch.items.plan_scene_file` with at most
``workers`` scenes in flight. A scene that raises becomes its own row already (the task never
raises); a scene that kills its worker (a segfault in a native library, a ``kill -9``) breaks
the pool, and loky reports the death on every task then in flight. Those few scenes are run
again one at a time in a fresh pool: the one that kills its worker alone is the culprit, its
row says ``crashed``, and the others are planned. On a ``dask.distributed`` cluster
(:mod:`planning.batch.cluster`), each scene is a future of its own; the scheduler retries a
task whose worker died and reports ``KilledWorker`` when it keeps killing them.

``Ctrl-C`` (or ``SIGTERM``, which the CLI turns into the same) stops the pool at once,
killing its workers; :func:`run_batch` then returns every scene that finished (also those
whose result had not yet been collected), ``interrupted``.
"""

from __future__ import annotations

import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass
from pathlib import Path

from cpr_kin.common.names import shown
from planning.batch.cluster import run_on_cluster
from planning.batch.items import BatchItem, finished_items, plan_scene_file
from planning.errors import PlanningError

Task = Callable[..., BatchItem]
"""Plans one scene file into an output folder, ``(scene file, output folder) -> BatchItem``
(:func:`~planning.batch.items.plan_scene_file`); on a cluster it also takes ``gate=``."""


@dataclass(frozen=True)
class BatchRun:
    """What a batch did.

    Attributes:
        items: one per scene planned, in the order of the scene files (an interrupted batch
            lists only the scenes done).
        interrupted: stopped by ``Ctrl-C`` or ``SIGTERM`` before every scene was done.
    """

    items: list[BatchItem]
    interrupted: bool


def _outcome(future: Future[BatchItem], name: str) -> BatchItem:
    """The task's item; a task that could not run (pickling, the pool) becomes an ``error`` row."""
    try:
        return future.result()
    except Exception as exc:
        return BatchItem.failed(name, "error", f"{type(exc).__name__}: {shown(str(exc))}")


def _run_local(
    task: Task, tasks: Sequence[tuple[Path, Path]], workers: int, done: Callable[[int, BatchItem], None]
) -> None:
    from loky import get_reusable_executor
    from loky.process_executor import BrokenProcessPool

    pending = deque(range(len(tasks)))
    executor = get_reusable_executor(max_workers=workers)
    in_flight: dict[Future[BatchItem], int] = {}
    try:
        while pending or in_flight:
            while pending and len(in_flight) < workers:
                index = pending.popleft()
                in_flight[executor.submit(task, *tasks[index])] = index
            finished, _ = wait(in_flight, return_when=FIRST_COMPLETED)
            broken = False
            for future in finished:
                if isinstance(future.exception(), BrokenProcessPool):
                    broken = True
                    continue
                index = in_flight.pop(future)
                done(index, _outcome(future, tasks[index][0].stem))
            if broken:  # every scene in flight is a suspect: run each alone to find the culprit
                suspects = sorted(in_flight.values())
                in_flight.clear()
                for index in suspects:
                    done(index, _alone(task, tasks[index]))
                executor = get_reusable_executor(max_workers=workers)
    except BaseException:
        for index, item in finished_items({f: i for f, i in in_flight.items() if f.done()}):
            done(index, item)
        executor.shutdown(wait=False, kill_workers=True)
        raise


def _alone(task: Task, arguments: tuple[Path, Path]) -> BatchItem:
    """Run one scene in a pool of its own: a crash there is this scene's."""
    from loky import get_reusable_executor
    from loky.process_executor import BrokenProcessPool

    started = time.perf_counter()
    future = get_reusable_executor(max_workers=1).submit(task, *arguments)
    if isinstance(future.exception(), BrokenProcessPool):
        died = "the worker process died while planning this scene"
        return BatchItem.failed(arguments[0].stem, "crashed", died, started)
    return _outcome(future, arguments[0].stem)


def check_workers(workers: int | None, scheduler: str | None) -> None:
    """Refuse a count of local workers below 1, or one given with a cluster's ``scheduler``.

    Raises:
        PlanningError: naming the value and what is allowed.
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise PlanningError(f"workers = {workers!r} must be an integer >= 1 (or None: every core)")
    if workers is not None and scheduler is not None:
        raise PlanningError(
            f"workers = {workers} limits local processes; on a Dask cluster its workers' threads "
            "decide how many scenes run at once: leave workers out with a scheduler"
        )


def run_batch(
    paths: Sequence[Path],
    out: Path,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[BatchItem], None] | None = None,
    task: Task = plan_scene_file,
) -> BatchRun:
    """Plan every scene file in parallel; outputs go to ``out/<stem>/``.

    Args:
        paths: scene files.
        out: output folder.
        workers: parallel scenes locally, at least 1 (default: every core); not with a
            ``scheduler``, whose workers' threads decide.
        scheduler: address of a ``dask.distributed`` scheduler, e.g. ``tcp://127.0.0.1:8786``.
        progress: called with each item as it completes.
        task: what plans one scene, ``(scene file, output folder) -> BatchItem`` (default
            :func:`~planning.batch.items.plan_scene_file`; the tests pass one that crashes).

    Raises:
        PlanningError: ``workers`` below 1 or given with a ``scheduler``; no Dask, or an
            unreachable scheduler.
    """
    from loky import cpu_count

    check_workers(workers, scheduler)

    tasks = [(path, out / path.stem) for path in paths]
    results: dict[int, BatchItem] = {}

    def done(index: int, item: BatchItem) -> None:
        results[index] = item
        if progress is not None:
            progress(item)

    try:
        if scheduler is None:
            _run_local(task, tasks, min(workers or cpu_count(), len(tasks)), done)
        else:
            run_on_cluster(task, tasks, scheduler, done)
    except KeyboardInterrupt:
        return BatchRun([results[i] for i in sorted(results)], interrupted=True)
    return BatchRun([results[i] for i in sorted(results)], interrupted=False)
