"""Where the toolkit keeps what it computed or downloaded once, between processes.

``$CPR_FIREFLY_CACHE``, else ``$XDG_CACHE_HOME/cpr-firefly``, else ``~/.cache/cpr-firefly``.
Entries are small JSON documents or NumPy arrays named by a digest of what they were computed from, written
whole (to a temporary file, then renamed) so that a reader never sees half of one. A folder
that cannot be written is no error: the value is computed again next time.
"""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray


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
    path = cache_folder() / kind / f"{digest}.json"
    with contextlib.suppress(OSError, ValueError):
        found = json.loads(path.read_text())
        if isinstance(found, dict):
            return found
    value = compute()
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f".{os.getpid()}.part")
        partial.write_text(json.dumps(value))
        partial.replace(path)
    return value


def cached_array(kind: str, digest: str, compute: Callable[[], NDArray[Any]]) -> NDArray[Any]:
    """The array cached as ``kind/digest.npy``, computed by ``compute`` and kept when absent.

    As :func:`cached_json`: an unreadable file is computed again and replaced; an array is read
    without pickles.
    """
    path = cache_folder() / kind / f"{digest}.npy"
    with contextlib.suppress(OSError, ValueError):
        found: NDArray[Any] = np.load(path, allow_pickle=False)
        return found
    value = compute()
    with contextlib.suppress(OSError):
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f".{os.getpid()}.part")
        with partial.open("wb") as stream:
            np.save(stream, value, allow_pickle=False)
        partial.replace(path)
    return value
