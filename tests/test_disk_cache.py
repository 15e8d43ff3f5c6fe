"""The disk cache: computed once, kept whole, recomputed when unreadable, shared by threads and processes."""

from __future__ import annotations

import json
import os
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from cpr_kin.common.disk_cache import (
    cache_folder,
    cached_array,
    cached_json,
    keep_file,
    kept_file,
    read_array,
    write_array,
)


@pytest.fixture
def folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def test_a_value_is_computed_once_and_read_back(folder: Path) -> None:
    calls: list[int] = []

    def compute() -> dict[str, object]:
        calls.append(1)
        return {"excess_m": [0.01, 0.02]}

    assert cache_folder() == folder
    assert cached_json("kind", "abc", compute) == {"excess_m": [0.01, 0.02]}
    assert cached_json("kind", "abc", compute) == {"excess_m": [0.01, 0.02]}
    assert len(calls) == 1
    assert json.loads((folder / "kind" / "abc.json").read_text()) == {"excess_m": [0.01, 0.02]}
    array = cached_array("arrays", "def", lambda: np.arange(6.0).reshape(2, 3))
    np.testing.assert_array_equal(cached_array("arrays", "def", lambda: np.zeros(1)), array)


def test_a_file_cut_short_is_computed_again_and_replaced(folder: Path) -> None:
    (folder / "kind").mkdir(parents=True)
    (folder / "kind" / "abc.json").write_text('{"excess_m": [0.0')
    assert cached_json("kind", "abc", lambda: {"v": 1}) == {"v": 1}
    assert json.loads((folder / "kind" / "abc.json").read_text()) == {"v": 1}


def test_threads_writing_one_entry_at_once_leave_it_whole(folder: Path) -> None:
    # a Dask worker's threads load the same robot at once: each writes a file of its own, then renames
    value: dict[str, object] = {"points": list(range(20_000))}

    def compute() -> dict[str, object]:
        time.sleep(0.01)  # all of them past the read, then writing together
        return value

    found: list[dict[str, object]] = []
    threads = [
        threading.Thread(target=lambda: found.append(cached_json("k", "d", compute))) for _ in range(8)
    ]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert found == [value] * 8
    assert json.loads((folder / "k" / "d.json").read_text()) == value
    assert sorted(p.name for p in (folder / "k").iterdir()) == ["d.json"]  # no part left behind


def test_a_folder_that_cannot_be_written_is_no_error(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(blocker / "cache"))
    assert cached_json("kind", "abc", lambda: {"v": 2}) == {"v": 2}
    write_array("kind", "abc", np.ones(3))
    assert read_array("kind", "abc") is None


def test_an_array_written_is_read_back_whole_and_replaced(folder: Path) -> None:
    assert read_array("kept", "abc") is None
    write_array("kept", "abc", np.arange(4.0))
    write_array("kept", "abc", np.arange(3, dtype=np.float32))
    found = read_array("kept", "abc")
    assert found is not None and found.dtype == np.float32
    np.testing.assert_array_equal(found, [0.0, 1.0, 2.0])
    assert sorted(p.name for p in (folder / "kept").iterdir()) == ["abc.npy"]  # no part left behind


def test_an_array_that_is_not_valid_is_computed_again_and_replaced(folder: Path) -> None:
    def indices(found: np.ndarray) -> bool:
        return found.dtype == np.int64 and found.ndim == 1

    write_array("kind", "abc", np.arange(3.0))  # floats where indices are kept: edited
    np.testing.assert_array_equal(cached_array("kind", "abc", lambda: np.arange(2), indices), [0, 1])
    found = read_array("kind", "abc")
    assert found is not None and indices(found)


def test_a_file_kept_is_found_and_marked_used(folder: Path) -> None:
    assert kept_file("models", "a.bin") is None
    keep_file("models", "a.bin", lambda path: path.write_bytes(b"model"), most_bytes=100)
    found = kept_file("models", "a.bin")
    assert found == folder / "models" / "a.bin" and found.read_bytes() == b"model"
    os.utime(found, (1.0, 1.0))
    assert kept_file("models", "a.bin") is not None and found.stat().st_mtime > 1.0


def test_files_kept_beyond_the_bytes_go_least_recently_used_first(folder: Path) -> None:
    for k, name in enumerate(("a.bin", "b.bin", "c.bin")):
        keep_file("models", name, lambda path: path.write_bytes(b"x" * 10), most_bytes=30)
        os.utime(folder / "models" / name, (1000.0 + k, 1000.0 + k))
    kept_file("models", "a.bin")  # the oldest, read: now the newest
    keep_file("models", "d.bin", lambda path: path.write_bytes(b"x" * 15), most_bytes=30)
    assert sorted(p.name for p in (folder / "models").iterdir()) == ["a.bin", "d.bin"]  # 25 bytes
    keep_file("models", "e.bin", lambda path: path.write_bytes(b"x" * 40), most_bytes=30)
    assert sorted(p.name for p in (folder / "models").iterdir()) == ["e.bin"]  # alone above: it stays


def test_a_save_that_fails_keeps_nothing_and_leaves_no_part(folder: Path) -> None:
    def failing(path: Path) -> None:
        path.write_bytes(b"half")
        raise RuntimeError("disk full")

    keep_file("models", "a.bin", failing, most_bytes=100)
    assert kept_file("models", "a.bin") is None
    assert list((folder / "models").iterdir()) == []


def test_arrays_beyond_the_bytes_go_least_recently_read_or_written_first(folder: Path) -> None:
    for k, name in enumerate(("a", "b", "c")):
        write_array("kept", name, np.zeros(100))  # 928 bytes each, header included
        os.utime(folder / "kept" / f"{name}.npy", (1000.0 + k, 1000.0 + k))
    assert read_array("kept", "a") is not None  # the oldest, read: now the newest
    write_array("kept", "d", np.zeros(100), most_bytes=2000)
    assert sorted(p.name for p in (folder / "kept").iterdir()) == ["a.npy", "d.npy"]
