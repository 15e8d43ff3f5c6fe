"""The project's just-in-time compiler: Numba's ``njit``, typed for mypy.

Hot loops that NumPy can only express as many small array operations (a per-configuration
kinematic chain, the firefly sweep) are compiled with Numba instead. Compiled code is cached
on disk (``cache=True``), so only the first run on a machine pays for compilation. Setting
``NUMBA_DISABLE_JIT=1`` runs the same functions as plain Python, for debugging.

Numba checks a cached function against its own file only: a kernel that calls or inlines a
function of another file (``batch_kinematics.place_capsule`` in the bound kernels) keeps the
old code when that file changes, and computes with it, silently. An installed package does not
change; in a source checkout (a ``.git`` beside the packages) :func:`forget_stale_kernels` drops
every cached kernel of the checkout when a file that compiles one has changed, before any is loaded.

A compilation keeps a first run waiting with nothing to show for it; the first of a process is
said on the logger :data:`COMPILE_LOG` (``INFO``), which ``cpr-plan`` prints on stderr.
"""

from __future__ import annotations

import hashlib
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar, cast

import numba
import numba.core.event

F = TypeVar("F", bound=Callable[..., Any])


def njit(function: F) -> F:
    """Compile ``function`` in nopython mode, cached, releasing the GIL."""
    return cast(F, numba.njit(cache=True, nogil=True)(function))


def njit_inline(function: F) -> F:
    """:func:`njit`, and inlined into the compiled functions that call it.

    For a small helper called in a compiled loop: passing it arrays costs their reference
    counts at every call, which can outweigh its work (``docs/benchmarks.md``, stop 59).
    """
    return cast(F, numba.njit(cache=True, nogil=True, inline="always")(function))


CHECKOUT = Path(__file__).resolve().parents[2]
"""The folder holding the package: a source checkout's root where it holds ``.git``."""
KERNEL_MARK = b"common.compiled import"
"""What a file that compiles a kernel holds (its import of this module)."""
STAMP = Path(__file__).resolve().parent / "__pycache__" / "kernel-sources.txt"
"""Where the checkout's kernel sources were last seen: their files' stat and their bytes' digest."""


COMPILE_LOG = logging.getLogger("cpr_kin.compiled")
"""Where :class:`FirstCompile` says that kernels are being compiled."""
COMPILING = (
    "compiling the numba kernels, which the first run on a machine (or after an update) does once: "
    "tens of seconds; later runs load them from the disk cache"
)
"""What :class:`FirstCompile` says."""


class FirstCompile(numba.core.event.Listener):
    """Says :data:`COMPILING` on ``log`` (``INFO``) at the first kernel numba compiles, once.

    Numba announces a compilation (its event ``numba:compile``) only where its disk cache holds
    no code for the kernel: a kernel loaded from the cache says nothing.
    """

    def __init__(self, log: logging.Logger = COMPILE_LOG) -> None:
        self.log, self.said = log, False

    def on_start(self, event: Any) -> None:
        """Say it, the first time."""
        if not self.said:
            self.said = True
            self.log.info(COMPILING)

    def on_end(self, event: Any) -> None:
        """Nothing: the start was said."""


def forget_stale_kernels(root: Path = CHECKOUT, stamp: Path = STAMP) -> bool:
    """In the source checkout ``root``, delete the cached kernels if a kernel's file changed since.

    The files of ``root``'s packages that import this module are hashed (their paths and bytes);
    the digest is kept in ``stamp``, with the sizes and times of every file of the packages, so
    that a checkout where none changed costs a few ``stat`` calls. Where the digest differs,
    every Numba cache file (``__pycache__/*.nbi``, ``*.nbc``) under the packages is deleted, and
    the kernels compile again on their first call. Whether any was deleted; nothing outside a
    checkout (no ``root/.git``), and ``False`` where a file cannot be read, deleted or written
    (the import goes on).
    """
    try:
        return _forget_stale_kernels(root, stamp)
    except OSError:
        return False


def _forget_stale_kernels(root: Path, stamp: Path) -> bool:
    """:func:`forget_stale_kernels`, its file errors raised."""
    if not (root / ".git").exists():
        return False
    files = sorted(_package_files(str(root)))
    stats = [(f, os.stat(f)) for f in files]
    seen = hashlib.sha256(repr([(f, st.st_size, st.st_mtime_ns) for f, st in stats]).encode()).hexdigest()
    try:
        last_seen, last_digest = stamp.read_text().split()
    except (OSError, ValueError):
        last_seen = last_digest = ""
    if seen == last_seen:
        return False
    digest = hashlib.sha256()
    for file in files:
        data = Path(file).read_bytes()
        if KERNEL_MARK in data:
            digest.update(os.path.relpath(file, root).encode() + b"\0" + data)
    stale = set() if digest.hexdigest() == last_digest else {os.path.dirname(f) for f in files}
    deleted = [p for folder in stale for p in Path(folder, "__pycache__").glob("*.nb[ic]")]
    for path in deleted:
        path.unlink(missing_ok=True)
    stamp.parent.mkdir(exist_ok=True)
    stamp.write_text(f"{seen} {digest.hexdigest()}")
    return bool(deleted)


def _package_files(root: str) -> list[str]:
    """The ``.py`` files of the packages at ``root`` (folders with an ``__init__.py``), bytecode skipped."""
    found = []
    for name in os.listdir(root):
        package = os.path.join(root, name)
        if not os.path.isfile(os.path.join(package, "__init__.py")):
            continue
        for folder, subfolders, names in os.walk(package):
            subfolders[:] = [sub for sub in subfolders if sub != "__pycache__"]
            found += [os.path.join(folder, file) for file in names if file.endswith(".py")]
    return found


forget_stale_kernels()
numba.core.event.register("numba:compile", FirstCompile())  # type: ignore[no-untyped-call]
