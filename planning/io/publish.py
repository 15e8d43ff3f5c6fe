"""Writing outputs so that a reader never sees a partial or mixed set, and two writers never mix.

A plan's files are *published as a whole* (:class:`OutputFolder`):

1. A lock, ``fcntl.flock`` on ``<parent>/.<name>.lock``, is held from before planning to the
   end: a second writer into the same folder stops at once with a message naming the first
   one's process. The kernel releases the lock when its process ends, even killed; a
   ``SIGINT`` or ``SIGTERM`` while the lock is taken or given back waits for that to end, so
   that an interrupted command leaves no lock file behind.
2. The files go into a new hidden folder beside the target, each flushed to disk, with
   ``manifest.json`` listing every file and its SHA-256.
3. Two renames put it in place: the previous set (if any) aside, the new set in; then the
   previous set is removed. Only between the renames is the target missing: a reader sees
   nothing then, never half a set. ``SIGINT`` and ``SIGTERM`` wait for the end of this step
   (:mod:`planning.io.uninterrupted`), so that an interrupted command leaves either its new
   set in place, tidied, or the previous one (:attr:`OutputFolder.published` tells which).
4. What a killed writer left (``.<name>.new-*``, ``.<name>.old-*``) is rolled back or removed
   by the next writer, under the lock: a previous set put aside returns if no new one took
   its place.

A target that exists must be empty or hold only files a plan writes (:data:`OUTPUT_NAMES`):
a mistyped ``--out`` never replaces somebody's folder. Single files (:func:`write_file`) are
written to a temporary name and renamed. Files and folders get the permissions ``open`` and
``mkdir`` would give them under the user's umask.
"""

from __future__ import annotations

import contextlib
import fcntl
import hashlib
import json
import os
import shutil
from collections.abc import Iterable
from pathlib import Path
from types import TracebackType
from typing import Any

from planning.errors import PlanningError
from planning.io.file_formats import OUTPUTS
from planning.io.uninterrupted import uninterrupted

MANIFEST = "manifest.json"
OUTPUT_NAMES = frozenset(
    {MANIFEST, "trajectory.json", "samples.csv", "report.md", "viewer.html"}
    | {"joints.png", "tcp_path.png", "clearance.png", "utilisation.png", "convergence.png"}
)
"""Every file a plan may write: a folder holding only these is a previous set, which a new
one may replace."""


class OutputError(PlanningError):
    """An output folder cannot be used: not a folder, not ours, or locked by another writer."""


Content = str | bytes | Iterable[str]
"""What a file is written from: its text or bytes, or its text in parts (streamed, never whole
in memory)."""


def _write(path: Path, content: Content) -> None:
    """Create ``path`` (which must not exist) with ``content``, flushed to disk, umask permissions."""
    parts = [content] if isinstance(content, str | bytes) else content
    descriptor = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # the umask applies
    with os.fdopen(descriptor, "wb") as stream:
        for part in parts:
            stream.write(part.encode("utf-8") if isinstance(part, str) else part)
        stream.flush()
        os.fsync(stream.fileno())


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def write_file(path: str | Path, content: Content) -> Path:
    """Write one file atomically: to ``.<name>.tmp-<pid>-<random>`` beside it, then renamed over it.

    ``content`` given in parts (an iterable of str) is written part by part: a large file
    needs no more memory than its largest part; if making a part fails, nothing is left.

    Temporary files that a killed writer left beside it are removed.

    Raises:
        OutputError: ``path`` names a folder, a device, a pipe or no file, or cannot be written
            (naming it).
    """
    path = Path(path)
    if not path.name or path.name in (".", ".."):
        raise OutputError(f"'{path}' names no file")
    if path.is_dir():
        raise OutputError(f"'{path}' is a folder; give a file name")
    if path.exists() and not path.is_file():  # renamed over, /dev/null would become a file
        raise OutputError(f"'{path}' is not a regular file (a device, a pipe or a socket); give a file name")
    prefix = f".{path.name}.tmp-"
    temporary = path.with_name(f"{prefix}{os.getpid()}-{os.urandom(4).hex()}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        for stale in path.parent.iterdir():
            pid = stale.name.removeprefix(prefix).split("-")[0]
            if stale.name.startswith(prefix) and pid.isdigit() and not _alive(int(pid)):
                stale.unlink(missing_ok=True)
        _write(temporary, content)
        os.replace(temporary, path)
    except OSError as exc:  # named by the file asked for, not the temporary one beside it
        raise OutputError(f"cannot write '{path}': {exc.strerror or exc}") from None
    finally:
        temporary.unlink(missing_ok=True)
    return path


def _manifest(files: dict[str, str | bytes]) -> str:
    digests = {
        name: hashlib.sha256(content.encode("utf-8") if isinstance(content, str) else content).hexdigest()
        for name, content in sorted(files.items())
    }
    return json.dumps({"format": OUTPUTS, "sha256": digests}, indent=1) + "\n"


def complete_set(folder: Path) -> bool:
    """Whether ``folder`` holds a whole published set: its manifest's files, each as written."""
    try:
        listed: dict[str, Any] = json.loads((folder / MANIFEST).read_text())["sha256"]
        present = {p.name for p in folder.iterdir()}
        if present != set(listed) | {MANIFEST}:
            return False
        return all(hashlib.sha256((folder / n).read_bytes()).hexdigest() == d for n, d in listed.items())
    except (OSError, ValueError, KeyError, TypeError):
        return False


class FolderLock:
    """Exclusive use of a folder by one writer, for as long as the context lasts.

    ``fcntl.flock`` on ``<parent>/.<name>.lock``; a second writer gets an
    :class:`OutputError` at once, naming the first one's process.
    """

    def __init__(self, path: str | Path) -> None:
        if not str(path).strip():
            raise OutputError("the output folder is empty (--out ''); name a folder")
        self.path = Path(path)
        self.target = self.path.resolve()
        if self.target == Path.cwd().resolve() or self.target in Path.cwd().resolve().parents:
            raise OutputError(f"output folder '{path}' is the current folder or holds it; name a subfolder")
        if self.target.exists() and not self.target.is_dir():
            raise OutputError(f"output folder '{path}' is a file; name a folder")
        self._lock_path = self.target.parent / f".{self.target.name}.lock"
        self._lock: int | None = None

    @property
    def held(self) -> bool:
        """Whether this object holds the lock now."""
        return self._lock is not None

    def __enter__(self) -> FolderLock:
        try:
            self.target.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise OutputError(f"cannot create '{self.target.parent}': {exc.strerror or exc}") from None
        try:  # a signal waits until the lock is ours, then finds it released and its file removed
            with uninterrupted():
                self._lock = _acquire(self._lock_path, self.path)
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        with uninterrupted():  # the file goes with the lock, whatever signal comes
            if self._lock is not None:
                with contextlib.suppress(OSError):
                    self._lock_path.unlink()  # while still locked: the next writer makes a new one
                os.close(self._lock)
                self._lock = None


class OutputFolder(FolderLock):
    """The folder a command publishes its files into, locked while the command runs.

    Use it as a context manager around the whole command (planning included), so that a
    second command into the same folder is refused before it spends any time::

        with OutputFolder(out) as folder:
            result = plan(scene)
            folder.publish(plan_files(result))

    Raises:
        OutputError: empty or current-folder path, a file, a folder that is not a previous
            set of outputs, or another writer holding the lock.
    """

    published = False
    """Whether :meth:`publish` has put a new, complete set in place."""

    def __enter__(self) -> OutputFolder:
        super().__enter__()
        try:
            self._recover()
            if self.target.is_dir():
                foreign = sorted(p.name for p in self.target.iterdir() if p.name not in OUTPUT_NAMES)
                if foreign:
                    shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
                    raise OutputError(
                        f"output folder '{self.path}' holds files a plan does not write ({shown}); "
                        "name a new or empty folder"
                    )
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _leftovers(self, kind: str) -> list[Path]:
        prefix = f".{self.target.name}.{kind}-"
        return sorted(p for p in self.target.parent.iterdir() if p.name.startswith(prefix))

    def _recover(self) -> None:
        """Roll back or remove what a killed writer left (we hold the lock: it is dead)."""
        for old in self._leftovers("old"):
            if not self.target.exists() and complete_set(old):
                os.rename(old, self.target)  # killed between the renames: the previous set returns
            else:
                shutil.rmtree(old, ignore_errors=True)
        for new in self._leftovers("new"):
            shutil.rmtree(new, ignore_errors=True)

    def publish(self, files: dict[str, str | bytes]) -> list[Path]:
        """Replace the folder's content by ``files`` (name -> text or bytes) and their manifest."""
        if not self.held:
            raise OutputError("publish() needs the folder entered: use 'with OutputFolder(path) as folder:'")
        unknown = sorted(set(files) - OUTPUT_NAMES)
        if unknown or MANIFEST in files:
            raise OutputError(
                f"cannot publish {unknown or [MANIFEST]}; allowed: {sorted(OUTPUT_NAMES - {MANIFEST})}"
            )
        target, token = self.target, f"{os.getpid()}-{os.urandom(4).hex()}"
        new = target.parent / f".{target.name}.new-{token}"
        try:
            new.mkdir()
            for name, content in {**files, MANIFEST: _manifest(files)}.items():
                _write(new / name, content)
        except BaseException:
            shutil.rmtree(new, ignore_errors=True)
            raise
        old = target.parent / f".{target.name}.old-{token}"
        with uninterrupted():  # a signal waits: the swap and the tidying are one step
            if target.exists():
                os.rename(target, old)
            os.rename(new, target)
            self.published = True
            shutil.rmtree(old, ignore_errors=True)
        return [self.path / name for name in [*files, MANIFEST]]


def _acquire(lock_path: Path, shown: Path) -> int:
    """Hold the lock file (created if need be); an OutputError naming the holder if it is taken."""
    for _ in range(10):  # a holder may remove the file between our open and our lock: retry
        descriptor = os.open(lock_path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.read(descriptor, 32).decode(errors="replace").strip() or "?"
            os.close(descriptor)
            raise OutputError(
                f"output folder '{shown}' is being written by another cpr-plan (process {holder}); "
                "wait for it to finish or name another folder"
            ) from None
        with contextlib.suppress(FileNotFoundError):
            if os.fstat(descriptor).st_ino == lock_path.stat().st_ino:
                os.ftruncate(descriptor, 0)
                os.write(descriptor, str(os.getpid()).encode())
                return descriptor
        os.close(descriptor)  # we locked a file its holder had just removed
    raise OutputError(f"cannot lock output folder '{shown}'")
