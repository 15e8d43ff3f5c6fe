"""Where the toolkit keeps what it computed or downloaded once, between processes.

``$CPR_FIREFLY_CACHE``, else ``$XDG_CACHE_HOME/cpr-firefly``, else ``~/.cache/cpr-firefly``.
Entries are small JSON documents or NumPy arrays named by a digest of what they were computed
from, written whole (to a temporary file, then renamed) so that a reader never sees half of
one. A folder that cannot be written is no error: the value is computed again next time.
"""

from __future__ import annotations

import contextlib
import json
import os
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any, BinaryIO, TypeVar

import numpy as np
from numpy.typing import NDArray

T = TypeVar("T")


def cache_folder() -> Path:
    """Where cached files are kept (module docstring)."""
    if os.environ.get("CPR_FIREFLY_CACHE"):
        return Path(os.environ["CPR_FIREFLY_CACHE"])
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "cpr-firefly"


def cached_json(kind: str, digest: str, compute: Callable[[], dict[str, Any]]) -> dict[str, Any]:
    """The document cached as ``kind/digest.json``, computed by ``compute`` and kept when absent.

    A cached file that is unreadable (cut short, edited) is computed again and replaced.
    """

    def read(path: Path) -> dict[str, Any] | None:
        found = json.loads(path.read_text())
        return found if isinstance(found, dict) else None

    return _cached(
        cache_folder() / kind / f"{digest}.json", read, lambda v, s: s.write(json.dumps(v).encode()), compute
    )


def cached_array(kind: str, digest: str, compute: Callable[[], NDArray[Any]]) -> NDArray[Any]:
    """The array cached as ``kind/digest.npy``, computed by ``compute`` and kept when absent.

    As :func:`cached_json`: an unreadable file is computed again and replaced; an array is read
    without pickles.
    """

    def read(path: Path) -> NDArray[Any]:
        found: NDArray[Any] = np.load(path, allow_pickle=False)
        return found

    return _cached(
        cache_folder() / kind / f"{digest}.npy", read, lambda v, s: np.save(s, v, allow_pickle=False), compute
    )


def _cached(
    path: Path,
    read: Callable[[Path], T | None],
    write: Callable[[T, BinaryIO], object],
    compute: Callable[[], T],
) -> T:
    """The value kept at ``path`` (``read``; unreadable or ``None``: absent), else ``compute``'s, kept whole.

    Written to a temporary file of the writer's own (process and thread), then renamed: a reader
    never sees half of one. A folder that cannot be written is no error.
    """
    with contextlib.suppress(OSError, ValueError):
        found = read(path)
        if found is not None:
            return found
    value = compute()
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f".{os.getpid()}.{threading.get_ident()}.part")  # a writer's own
        with partial.open("wb") as stream:
            write(value, stream)
        partial.replace(path)
    return value
