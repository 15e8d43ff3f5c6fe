"""Where the toolkit keeps what it computed or downloaded once, between processes.

``$CPR_FIREFLY_CACHE``, else ``$XDG_CACHE_HOME/cpr-firefly``, else ``~/.cache/cpr-firefly``.
Entries are small JSON documents, NumPy arrays or other libraries' files (:func:`keep_file`)
named by a digest of what they were computed from, written whole (to a temporary file, then
renamed) so that a reader never sees half of one. A folder that cannot be written is no error:
the value is computed again next time.
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


def cached_array(
    kind: str,
    digest: str,
    compute: Callable[[], NDArray[Any]],
    valid: Callable[[NDArray[Any]], bool] | None = None,
) -> NDArray[Any]:
    """The array cached as ``kind/digest.npy``, computed by ``compute`` and kept when absent.

    As :func:`cached_json`: an unreadable file is computed again and replaced; an array is read
    without pickles. ``valid``: what a kept array must satisfy to be read (its shape, dtype and
    range, which a file cut short or edited need not keep); one that fails is computed again.
    """

    def read(path: Path) -> NDArray[Any] | None:
        found = _read_npy(path)
        return found if valid is None or valid(found) else None

    return _cached(cache_folder() / kind / f"{digest}.npy", read, _write_npy, compute)


def read_array(kind: str, digest: str) -> NDArray[Any] | None:
    """The array kept as ``kind/digest.npy``, marked as just used; ``None``: none, or unreadable."""
    path = kept_file(kind, f"{digest}.npy")
    with contextlib.suppress(OSError, ValueError, EOFError):
        return None if path is None else _read_npy(path)
    return None


def write_array(kind: str, digest: str, value: NDArray[Any], most_bytes: int | None = None) -> None:
    """Keep ``value`` as ``kind/digest.npy``, whole, in place of what was there.

    As :func:`cached_json` writes: a reader never sees half of it; a folder that cannot be written
    is no error. ``most_bytes``: as :func:`keep_file`'s, the arrays of ``kind`` least recently
    kept or read (:func:`read_array`) removed beyond it; ``None``: none removed.
    """
    path = cache_folder() / kind / f"{digest}.npy"
    _write(path, value, _write_npy)
    if most_bytes is not None:
        _prune(path, most_bytes)


def kept_file(kind: str, name: str) -> Path | None:
    """The file kept as ``kind/name``, marked as just used (:func:`keep_file`); ``None`` where none is."""
    path = cache_folder() / kind / name
    if not path.is_file():
        return None
    with contextlib.suppress(OSError):  # a folder that cannot be written still reads
        os.utime(path)
    return path


def keep_file(kind: str, name: str, save: Callable[[Path], object], most_bytes: int) -> None:
    """Keep the file ``save`` writes to the path it is given as ``kind/name``; ``most_bytes`` of them at most.

    ``save`` writes to a temporary path of the writer's own, which is then renamed: a reader
    never sees half of it. Where the files of ``kind`` then add up to more than ``most_bytes``,
    those least recently kept or read (:func:`kept_file`) are removed until they do not (the
    one just kept stays): for entries of megabytes (a robot's meshes), which a new version of
    a robot or of the libraries leaves behind. A folder that cannot be written, or a ``save``
    that fails (``OSError``, ``RuntimeError``), is no error.
    """
    path = cache_folder() / kind / name
    if saved_whole(path, save):
        _prune(path, most_bytes)


def _prune(path: Path, most_bytes: int) -> None:
    """Remove the files beside ``path`` (its suffix) least recently used beyond ``most_bytes``, not it."""
    try:
        entries = [(_used_at(e), e) for e in path.parent.iterdir() if e.suffix == path.suffix and e != path]
        total = path.stat().st_size
    except OSError:
        return
    for _, entry in sorted(entries, reverse=True):  # the most recently used first
        with contextlib.suppress(OSError):  # one removed meanwhile by another process
            total += entry.stat().st_size
            if total > most_bytes:
                entry.unlink()


def _used_at(path: Path) -> float:
    """When ``path`` was last kept or read [s since the epoch]; ``-inf`` where it is gone."""
    try:
        return path.stat().st_mtime
    except OSError:
        return -float("inf")


def _read_npy(path: Path) -> NDArray[Any]:
    found: NDArray[Any] = np.load(path, allow_pickle=False)
    return found


def _write_npy(value: NDArray[Any], stream: BinaryIO) -> None:
    np.save(stream, value, allow_pickle=False)


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
    with contextlib.suppress(OSError, ValueError, EOFError):
        found = read(path)
        if found is not None:
            return found
    value = compute()
    _write(path, value, write)
    return value


def _write(path: Path, value: T, write: Callable[[T, BinaryIO], object]) -> None:
    """``value`` written to ``path`` by ``write`` on a stream, whole (:func:`saved_whole`)."""

    def save(partial: Path) -> None:
        with partial.open("wb") as stream:
            write(value, stream)

    saved_whole(path, save)


def saved_whole(path: Path, save: Callable[[Path], object]) -> bool:
    """Whether ``save`` wrote ``path`` whole, through a temporary file of the writer's own.

    The temporary file (the process's and thread's) is renamed: a reader never sees half. A
    folder that cannot be written, or a ``save`` that fails (``OSError``, or a library's
    ``RuntimeError``), is no error: nothing is kept, no temporary file is left.
    """
    partial = path.with_suffix(f".{os.getpid()}.{threading.get_ident()}.part")  # a writer's own
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        save(partial)
        partial.replace(path)
    except (OSError, RuntimeError):
        with contextlib.suppress(OSError):
            partial.unlink(missing_ok=True)
        return False
    return True
