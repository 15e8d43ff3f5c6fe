"""The files that compile the project's kernels: their digest, and numba's disk cache kept in step.

A file that compiles a kernel imports :mod:`cpr_kin.common.compiled` (:data:`KERNEL_MARK`).
Numba checks a cached function against its own file only: a kernel that calls or inlines a
function of another file (``batch_kinematics.place_capsule`` in the bound kernels) keeps the
old code when that file changes, and computes with it, silently. An installed package does not
change; in a source checkout (a ``.git`` beside the packages) :func:`forget_stale_kernels` drops
every cached kernel of the checkout when a file that compiles one has changed, before any is
loaded. :func:`sources_digest` names the kernels compiled ahead of time
(:mod:`cpr_kin.common.ahead`) after the same files and the warm-up that chooses their argument
types, so that a changed kernel is never run from an older build, nor a kernel newly warmed
left out of one.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

CHECKOUT = Path(__file__).resolve().parents[2]
"""The folder holding the packages: a source checkout's root where it holds ``.git``."""
PACKAGES = ("cpr_kin", "planning")
"""The packages whose files may compile a kernel."""
KERNEL_MARK = b"common.compiled import"
"""What a file that compiles a kernel holds (its import of :mod:`cpr_kin.common.compiled`)."""
SIGNATURE_SOURCES = ("planning/warming.py",)
"""Files, from the checkout's root, that choose which kernels are compiled ahead of time and with
which argument types (the warm-up the build runs): part of the digest too, so that a warm-up
that calls a kernel anew names a module yet to be built."""
STAMP = Path(__file__).resolve().parent / "__pycache__" / "kernel-sources.txt"
"""Where the checkout's kernel sources were last seen: their files' stat and their bytes' digest."""


def sources_digest(root: Path = CHECKOUT, stamp: Path = STAMP, packages: tuple[str, ...] = PACKAGES) -> str:
    """The SHA-256 of the files of ``packages`` under ``root`` that compile a kernel (paths and bytes).

    Kept in ``stamp`` beside the sizes and times of every file of the packages: where none
    changed, a few ``stat`` calls; a stamp that cannot be written is no error.
    """
    return _digests(root, stamp, packages)[1]


def forget_stale_kernels(
    root: Path = CHECKOUT, stamp: Path = STAMP, packages: tuple[str, ...] = PACKAGES
) -> bool:
    """In the source checkout ``root``, delete the cached kernels if a kernel's file changed since.

    The kernel files' digest (:func:`sources_digest`) is compared with the one ``stamp`` kept.
    Where they differ, every Numba cache file (``__pycache__/*.nbi``, ``*.nbc``) under
    ``packages`` is deleted, and the kernels compile again on their first call. Whether any was
    deleted; nothing outside a checkout (no ``root/.git``), and ``False`` where a file cannot be
    read or deleted (the import goes on).
    """
    if not (root / ".git").exists():
        return False
    try:
        last, digest = _digests(root, stamp, packages)
        if last == digest:
            return False
        folders = {os.path.dirname(f) for f in _package_files(str(root), packages)}
        deleted = [p for folder in folders for p in Path(folder, "__pycache__").glob("*.nb[ic]")]
        for path in deleted:
            path.unlink(missing_ok=True)
    except OSError:
        return False
    return bool(deleted)


def _digests(root: Path, stamp: Path, packages: tuple[str, ...]) -> tuple[str, str]:
    """The kernel files' digest ``stamp`` kept (``""``: none) and today's, which ``stamp`` then keeps."""
    files = sorted(_package_files(str(root), packages))
    stats = [(f, os.stat(f)) for f in files]
    seen = hashlib.sha256(repr([(f, st.st_size, st.st_mtime_ns) for f, st in stats]).encode()).hexdigest()
    try:
        last_seen, last_digest = stamp.read_text().split()
    except (OSError, ValueError):
        last_seen = last_digest = ""
    if seen == last_seen:
        return last_digest, last_digest
    digest = _kernels_digest(files, root)
    try:
        stamp.parent.mkdir(exist_ok=True)
        stamp.write_text(f"{seen} {digest}")
    except OSError:
        pass
    return last_digest, digest


def _kernels_digest(files: list[str], root: Path) -> str:
    """The SHA-256 of the paths (from ``root``) and bytes of ``files`` that compile a kernel or choose them.

    :data:`KERNEL_MARK` marks the first, :data:`SIGNATURE_SOURCES` names the others.
    """
    digest = hashlib.sha256()
    for file in files:
        data = Path(file).read_bytes()
        relative = os.path.relpath(file, root)
        if KERNEL_MARK in data or relative.replace(os.sep, "/") in SIGNATURE_SOURCES:
            digest.update(relative.encode() + b"\0" + data)
    return digest.hexdigest()


def _package_files(root: str, names: tuple[str, ...]) -> list[str]:
    """The ``.py`` files of the packages ``names`` at ``root`` (folders with an ``__init__.py``)."""
    found = []
    for name in names:
        package = os.path.join(root, name)
        if not os.path.isfile(os.path.join(package, "__init__.py")):
            continue
        for folder, subfolders, files in os.walk(package):
            subfolders[:] = [sub for sub in subfolders if sub != "__pycache__"]
            found += [os.path.join(folder, file) for file in files if file.endswith(".py")]
    return found
