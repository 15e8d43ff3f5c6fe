"""A batch on a ``dask.distributed`` cluster: a future per scene; an interrupt that leaves no stray file.

Every path a task gets is absolute (the caller's scene files and output folder): a worker
runs in a folder of its own. Each scene is a future; the scheduler retries a task whose
worker died and reports ``KilledWorker`` when it keeps killing them.

Dask cannot stop a task that is running. So each task publishes its files through a
:class:`PublishGate`: under a cluster-wide lock, only if the batch has not been stopped, and
it records its row on the cluster before it lets go of the lock. When the batch is
interrupted, the caller stops the gate under the same lock: from then on no scene writes a
file, and every scene that did is in the gate's record, so the summary lists every scene
whose files are on disk, also those whose result had not yet come back.
"""

from __future__ import annotations

import contextlib
import ipaddress
import logging
import uuid
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from cpr_kin.common.names import escaped, shown
from planning.batch.items import BatchItem, finished_items
from planning.errors import PlanningError

SCHEDULER_PROTOCOLS = ("tcp", "tls", "ws", "wss", "inproc", "ucx")
"""Protocols of a ``dask.distributed`` scheduler address."""
LOCK_TIMEOUT_S = 60.0
"""Longest wait for the gate's lock when stopping (a worker that died holding it frees it late)."""


def check_scheduler(address: str) -> None:
    """Refuse a scheduler address that is not ``PROTOCOL://HOST[:PORT]`` at once (no connection tried).

    Raises:
        PlanningError: an unknown protocol, no host, an invalid IP address or a port outside
            1-65535.
    """
    protocols = ", ".join(SCHEDULER_PROTOCOLS)
    expected = f"expected PROTOCOL://HOST:PORT, e.g. tcp://127.0.0.1:8786 (PROTOCOL: {protocols})"
    try:
        parts = urlsplit(address)
        hostname = parts.hostname
    except ValueError:  # e.g. an unclosed IPv6 bracket
        raise PlanningError(
            f"--scheduler = {shown(address)} is not a scheduler address; {expected}"
        ) from None
    extra = parts.path or parts.query or parts.fragment or parts.username or parts.password
    if parts.scheme not in SCHEDULER_PROTOCOLS or not hostname or extra:
        raise PlanningError(f"--scheduler = {shown(address)} is not a scheduler address; {expected}")
    try:
        port = parts.port
    except ValueError:
        port = -1
    if port is not None and not 1 <= port <= 65535:
        raise PlanningError(f"--scheduler = {shown(address)}: the port must be in [1, 65535]; {expected}")
    host = hostname
    if all(c.isdigit() or c == "." for c in host) or ":" in host:
        try:
            ipaddress.ip_address(host)
        except ValueError:
            raise PlanningError(f"--scheduler = {shown(address)}: '{host}' is not an IP address") from None
    elif not all(_label(part) for part in host.split(".")):
        raise PlanningError(f"--scheduler = {shown(address)}: {shown(host)} is not a host name")


def _label(part: str) -> bool:
    """Whether ``part`` is a host name's label: 1-63 letters, digits and inner hyphens."""
    return (
        0 < len(part) <= 63
        and part.replace("-", "").isalnum()
        and not part.startswith("-")
        and not part.endswith("-")
    )


@dataclass(frozen=True)
class PublishGate:
    """Lets a scene publish its files unless the batch was stopped, and records it (module docstring).

    A task enters ``gate(item)`` with the row it will report: the context yields whether it
    may publish, and records ``item`` once the block ends without an error. Picklable: the
    names of a Dask ``Lock``, ``Event`` and ``Queue`` of the batch, which the workers reach
    through their own client.

    Attributes:
        name: the batch's unique prefix of the three names.
    """

    name: str

    @classmethod
    def new(cls) -> PublishGate:
        """A gate of its own for one batch."""
        return cls(f"cpr-plan-batch-{uuid.uuid4().hex}")

    @contextlib.contextmanager
    def __call__(self, item: BatchItem) -> Iterator[bool]:
        """Within the lock: whether the scene may publish; its row recorded if it did."""
        from distributed import Event, Lock, Queue

        with Lock(f"{self.name}-lock"):
            if Event(f"{self.name}-stop").is_set():
                yield False
                return
            yield True
            Queue(f"{self.name}-published").put(item)

    def stop(self, client: Any) -> list[BatchItem]:
        """Let no scene publish from now on; the rows of every scene that did."""
        from distributed import Event, Lock, Queue

        lock = Lock(f"{self.name}-lock")  # on the default client: the caller's
        held = lock.acquire(timeout=LOCK_TIMEOUT_S)
        try:
            Event(f"{self.name}-stop", client=client).set()
            queue = Queue(f"{self.name}-published", client=client)
            return list(queue.get(batch=True))
        finally:
            if held:
                lock.release()


def run_on_cluster(
    task: Callable[..., BatchItem],
    tasks: Sequence[tuple[Path, Path]],
    scheduler: str,
    done: Callable[[int, BatchItem], None],
) -> None:
    """Run ``task(scene, out, gate=...)`` for each of ``tasks`` on the cluster; ``done(index, item)`` each.

    Raises:
        PlanningError: no Dask, or an unreachable scheduler.
        KeyboardInterrupt: interrupted; ``done`` has then been called for every scene that
            published its files.
    """
    try:
        from dask.distributed import Client, as_completed
        from distributed import KilledWorker
    except ImportError:
        raise PlanningError(
            "a Dask scheduler needs dask.distributed: pip install 'dask[distributed]'"
        ) from None
    try:
        client = Client(scheduler, timeout=10)
    except (OSError, TimeoutError, ValueError) as exc:
        raise PlanningError(f"cannot reach the Dask scheduler at {shown(scheduler)}: {exc}") from None
    gate = PublishGate.new()
    recorded: set[int] = set()

    def record(index: int, item: BatchItem) -> None:
        if index not in recorded:
            recorded.add(index)
            done(index, item)

    with client:
        futures: dict[Any, int] = {
            client.submit(task, *arguments, gate=gate, pure=False): index
            for index, arguments in enumerate(tasks)
        }
        try:
            for future in as_completed(futures):
                index, name = futures[future], tasks[futures[future]][0].stem
                try:
                    item = future.result()
                except KilledWorker:
                    item = BatchItem.failed(
                        name, "crashed", "the scene killed every Dask worker that planned it"
                    )
                except Exception as exc:
                    item = BatchItem.failed(name, "error", f"{type(exc).__name__}: {shown(str(exc))}")
                record(index, item)
        except BaseException:
            # a Ctrl-C inside distributed's sync() leaves a loop callback that fails later on a
            # missing future, and tornado would print its traceback over the one-line message
            logging.getLogger("tornado.application").setLevel(logging.CRITICAL)
            client.cancel([f for f, i in futures.items() if i not in recorded])
            published = {item.scene: item for item in gate.stop(client)}
            for index, (path, _) in enumerate(tasks):
                if escaped(path.stem) in published:  # a row names its scene escaped
                    record(index, published[escaped(path.stem)])
            finished = {f: i for f, i in futures.items() if i not in recorded and f.status == "finished"}
            for index, item in finished_items(finished):
                record(index, item)
            raise
