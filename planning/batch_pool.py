"""Running the scene tasks of a batch in parallel, so that nothing one scene does sinks the rest.

Locally, ``loky``'s process pool runs :func:`planning.batch.plan_scene_file` with at most
``workers`` scenes in flight. A scene that raises becomes its own row already (the task never
raises); a scene that kills its worker (a segfault in a native library, a ``kill -9``) breaks
the pool, and loky reports the death on every task then in flight. Those few scenes are run
again one at a time in a fresh pool: the one that kills its worker alone is the culprit, its
row says ``crashed``, and the others are planned. On a ``dask.distributed`` cluster, each
scene is a future of its own; the scheduler retries a task whose worker died and reports
``KilledWorker`` when it keeps killing them.

``Ctrl-C`` (or ``SIGTERM``, which the CLI turns into the same) stops the pool at once,
killing its workers; :func:`run_batch` then returns every scene that finished (also those
whose result had not yet been collected), ``interrupted``.
"""

from __future__ import annotations

import ipaddress
import time
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from planning.batch import BatchItem, plan_scene_file
from planning.errors import PlanningError
from planning.validation import shown

Task = Callable[[Path, Path], BatchItem]
"""Plans one scene file into an output folder: :func:`~planning.batch.plan_scene_file`."""


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
        _harvest({future: index for future, index in in_flight.items() if future.done()}, tasks, done)
        executor.shutdown(wait=False, kill_workers=True)
        raise


def _harvest(
    finished: dict[Any, int], tasks: Sequence[tuple[Path, Path]], done: Callable[[int, BatchItem], None]
) -> None:
    """Record the scenes of ``finished`` futures that completed, when a batch is interrupted."""
    for future, index in finished.items():
        try:
            item = future.result(timeout=1)
        except BaseException:  # cancelled, failed or still running: not a finished scene
            continue
        done(index, item)


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


def _run_dask(
    task: Task, tasks: Sequence[tuple[Path, Path]], scheduler: str, done: Callable[[int, BatchItem], None]
) -> None:
    try:
        from dask.distributed import Client, as_completed
        from distributed import KilledWorker
    except ImportError:
        raise PlanningError(
            "a Dask scheduler needs dask.distributed: pip install 'dask[distributed]'"
        ) from None
    try:
        client = Client(scheduler, timeout=10)  # type: ignore[no-untyped-call]
    except (OSError, TimeoutError) as exc:
        raise PlanningError(f"cannot reach the Dask scheduler at '{shown(scheduler)}': {exc}") from None
    with client:
        futures: dict[Any, int] = {
            client.submit(task, *arguments, pure=False): index for index, arguments in enumerate(tasks)
        }
        recorded: set[int] = set()
        try:
            for future in as_completed(futures):  # type: ignore[no-untyped-call]
                index, name = futures[future], tasks[futures[future]][0].stem
                recorded.add(index)
                try:
                    item = future.result()
                except KilledWorker:
                    item = BatchItem.failed(
                        name, "crashed", "the scene killed every Dask worker that planned it"
                    )
                except Exception as exc:
                    item = BatchItem.failed(name, "error", f"{type(exc).__name__}: {shown(str(exc))}")
                done(index, item)
        except BaseException:
            finished = {f: i for f, i in futures.items() if i not in recorded and f.status == "finished"}
            _harvest(finished, tasks, done)
            client.cancel(list(futures))  # type: ignore[no-untyped-call]
            raise


SCHEDULER_PROTOCOLS = ("tcp", "tls", "ws", "wss", "inproc", "ucx")
"""Protocols of a ``dask.distributed`` scheduler address."""


def check_scheduler(address: str) -> None:
    """Refuse a scheduler address that is not ``PROTOCOL://HOST[:PORT]`` at once (no connection tried).

    Raises:
        PlanningError: an unknown protocol, no host, an invalid IP address or a port outside
            1-65535.
    """
    protocols = ", ".join(SCHEDULER_PROTOCOLS)
    expected = f"expected PROTOCOL://HOST:PORT, e.g. tcp://127.0.0.1:8786 (PROTOCOL: {protocols})"
    parts = urlsplit(address)
    if parts.scheme not in SCHEDULER_PROTOCOLS or not parts.hostname:
        raise PlanningError(f"--scheduler = {shown(address)} is not a scheduler address; {expected}")
    try:
        port = parts.port
    except ValueError:
        port = -1
    if port is not None and not 1 <= port <= 65535:
        raise PlanningError(f"--scheduler = {shown(address)}: the port must be in [1, 65535]; {expected}")
    host = parts.hostname
    if all(c.isdigit() or c == "." for c in host) or ":" in host:
        try:
            ipaddress.ip_address(host)
        except ValueError:
            raise PlanningError(f"--scheduler = {shown(address)}: '{host}' is not an IP address") from None
    elif not all(
        label and len(label) <= 63 and label.replace("-", "").isalnum() for label in host.split(".")
    ):
        raise PlanningError(f"--scheduler = {shown(address)}: {shown(host)} is not a host name")


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
        workers: parallel scenes locally (default: every core).
        scheduler: address of a ``dask.distributed`` scheduler, e.g. ``tcp://127.0.0.1:8786``.
        progress: called with each item as it completes.
        task: what plans one scene, ``(scene file, output folder) -> BatchItem`` (default
            :func:`~planning.batch.plan_scene_file`; the tests pass one that crashes).

    Raises:
        PlanningError: no Dask, or an unreachable scheduler.
    """
    from loky import cpu_count

    tasks = [(path, out / path.stem) for path in paths]
    results: dict[int, BatchItem] = {}

    def done(index: int, item: BatchItem) -> None:
        results[index] = item
        if progress is not None:
            progress(item)

    try:
        if scheduler is None:
            _run_local(task, tasks, max(1, min(workers or cpu_count(), len(tasks))), done)
        else:
            _run_dask(task, tasks, scheduler, done)
    except KeyboardInterrupt:
        return BatchRun([results[i] for i in sorted(results)], interrupted=True)
    return BatchRun([results[i] for i in sorted(results)], interrupted=False)
