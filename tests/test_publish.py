from __future__ import annotations

import errno
import json
import os
import re
import signal
import stat
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from planning.io.publish import (
    MANIFEST,
    FolderLock,
    OutputError,
    OutputFolder,
    complete_set,
    write_file,
)

FILES: dict[str, str | bytes] = {
    "trajectory.json": '{"a": 1}\n',
    "report.md": "# report\n",
    "samples.csv": b"t\n0\n",
}


def test_a_set_is_published_with_its_manifest(tmp_path: Path) -> None:
    with OutputFolder(tmp_path / "out") as folder:
        written = folder.publish(FILES)
    assert sorted(p.name for p in written) == sorted([*FILES, MANIFEST])
    assert complete_set(tmp_path / "out")
    assert json.loads((tmp_path / "out" / MANIFEST).read_text())["format"] == "cpr-plan-outputs/1"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no lock, no temporary folder left


def test_a_new_set_replaces_the_previous_one_whole(tmp_path: Path) -> None:
    with OutputFolder(tmp_path / "out") as folder:
        folder.publish({**FILES, "viewer.html": "<html/>"})
    with OutputFolder(tmp_path / "out") as folder:
        folder.publish({"trajectory.json": "{}\n"})
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [MANIFEST, "trajectory.json"]
    assert complete_set(tmp_path / "out")


def test_files_get_the_users_umask(tmp_path: Path) -> None:
    previous = os.umask(0o027)
    try:
        with OutputFolder(tmp_path / "out") as folder:
            folder.publish(FILES)
        write_file(tmp_path / "single.txt", "x")
    finally:
        os.umask(previous)
    assert stat.S_IMODE((tmp_path / "out" / "report.md").stat().st_mode) == 0o640
    assert stat.S_IMODE((tmp_path / "out").stat().st_mode) == 0o750
    assert stat.S_IMODE((tmp_path / "single.txt").stat().st_mode) == 0o640


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda root: "", "the output folder is empty"),
        (lambda root: ".", "is the current folder or holds it"),
        (lambda root: str(root.parent), "is the current folder or holds it"),
        (lambda root: (root / "file").write_text("x") and str(root / "file"), "is a file; name a folder"),
    ],
)
def test_unusable_output_folders(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, make: object, message: str
) -> None:
    monkeypatch.chdir(tmp_path)
    with pytest.raises(OutputError, match=message), OutputFolder(make(tmp_path)):  # type: ignore[operator]
        pass


def test_a_folder_that_is_not_a_previous_set_is_never_replaced(tmp_path: Path) -> None:
    mine = tmp_path / "photos"
    mine.mkdir()
    (mine / "holiday.jpg").write_bytes(b"\xff\xd8")
    refused = r"holds files a plan does not write \(holiday\.jpg\)"
    with pytest.raises(OutputError, match=refused), OutputFolder(mine) as folder:
        folder.publish(FILES)
    assert (mine / "holiday.jpg").read_bytes() == b"\xff\xd8"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["photos"]


def test_a_second_writer_is_refused_naming_the_first(tmp_path: Path) -> None:
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; from planning.io.publish import FolderLock\n"
            "with FolderLock(sys.argv[1]):\n    print('held', flush=True); time.sleep(60)",
            str(tmp_path / "out"),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        refused = rf"being written by another cpr-plan \(process {holder.pid}\)"
        with pytest.raises(OutputError, match=refused), OutputFolder(tmp_path / "out"):
            pass
    finally:
        holder.kill()
        holder.wait()
    with OutputFolder(tmp_path / "out") as folder:  # the kernel released the killed holder's lock
        folder.publish(FILES)


@pytest.mark.parametrize("during", ["ftruncate", "flock"])
def test_a_signal_while_the_lock_is_taken_leaves_no_lock_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, during: str
) -> None:
    """Ctrl-C just after the lock file is created: the command stops, and leaves nothing behind."""
    import fcntl

    module = os if during == "ftruncate" else fcntl  # the modules publish calls into
    original = getattr(module, during)

    def interrupted(*args: object) -> object:
        signal.raise_signal(signal.SIGINT)  # Python's handler: KeyboardInterrupt
        return original(*args)

    monkeypatch.setattr(module, during, interrupted)
    with pytest.raises(KeyboardInterrupt), OutputFolder(tmp_path / "out"):
        pytest.fail("the interrupted command went on")  # pragma: no cover
    assert list(tmp_path.iterdir()) == []


def test_a_killed_writers_leftovers_are_rolled_back_or_removed(tmp_path: Path) -> None:
    with OutputFolder(tmp_path / "out") as folder:
        folder.publish(FILES)
    # as if a writer died between its two renames: the previous set aside, the new one beside it
    os.rename(tmp_path / "out", tmp_path / ".out.old-123-abcd")
    (tmp_path / ".out.new-123-abcd").mkdir()
    (tmp_path / ".out.new-123-abcd" / "trajectory.json").write_text("half")
    with OutputFolder(tmp_path / "out"):
        pass
    assert complete_set(tmp_path / "out")  # the previous set is back
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_publish_needs_the_lock_and_known_names(tmp_path: Path) -> None:
    folder = OutputFolder(tmp_path / "out")
    with pytest.raises(OutputError, match="needs the folder entered"):
        folder.publish(FILES)
    with folder, pytest.raises(OutputError, match=r"cannot publish \['notes.txt'\]"):
        folder.publish({"notes.txt": "x"})
    with FolderLock(tmp_path / "batch") as lock:
        assert lock.held
    assert not lock.held


def test_write_file_is_atomic_and_cleans_up_after_the_dead(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / ".out.json.tmp-999999999-dead").write_text("left by a killed writer")
    write_file(tmp_path / "out.json", "{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]

    def refuse(*_: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device", "/somewhere/.other.json.tmp-1-ab")

    monkeypatch.setattr(os, "replace", refuse)
    other = tmp_path / "other.json"  # named as asked for, not by the temporary file beside it
    named = rf"cannot write '{re.escape(str(other))}': No space left on device"
    with pytest.raises(OutputError, match=named):
        write_file(other, "{}")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.json"]
    with pytest.raises(OutputError, match="is a folder"):
        write_file(tmp_path, "x")


def test_a_file_is_never_renamed_over_a_device_or_a_pipe(tmp_path: Path) -> None:
    # as root, `--out /dev/null` replaced the device by a regular file: a FIFO stands for it here
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match=r"is not a regular file \(a device, a pipe or a socket\)"):
        write_file(fifo, "text\n")
    assert stat.S_ISFIFO(fifo.lstat().st_mode) and sorted(p.name for p in tmp_path.iterdir()) == ["pipe.yaml"]


def test_a_file_written_in_parts_that_fails_leaves_nothing(tmp_path: Path) -> None:
    def parts() -> Iterator[str]:
        yield "first part\n"
        raise RuntimeError("the producer failed")

    with pytest.raises(RuntimeError, match="the producer failed"):
        write_file(tmp_path / "big.yaml", parts())
    assert list(tmp_path.iterdir()) == []
