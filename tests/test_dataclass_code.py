"""The dataclasses' methods kept compiled: the same classes, no text compiled twice, a bad file ignored."""

from __future__ import annotations

import builtins
import dataclasses
import importlib.util
import inspect
import marshal
import os
import stat
import subprocess
import sys
import typing
from pathlib import Path
from typing import Any

import pytest

from planning.cli import dataclass_code
from planning.cli.dataclass_code import KeptCode, keep_dataclass_code, read_stored, reuse_dataclass_code

ROOT = Path(__file__).resolve().parents[1]
CLASS = '''
@dataclass(frozen=True)
class Pose:
    """A named pose [m, rad]."""
    name: str
    q: tuple[float, ...] = (0.0, 0.0)
    tags: tuple[str, ...] = field(default_factory=tuple)
    scale_m: float = 1.0
    notes: list[str] = field(default_factory=list, hash=False, compare=False)
'''


def made(compile_with: Any) -> Any:
    """``CLASS`` made with :mod:`dataclasses` compiling through ``compile_with``."""
    saved = dataclasses.__dict__.get("exec")
    dataclasses.exec = compile_with  # type: ignore[attr-defined]
    try:
        names: dict[str, Any] = {"dataclass": dataclasses.dataclass, "field": dataclasses.field}
        exec(CLASS, names)
        return names["Pose"]
    finally:
        if saved is None:
            del dataclasses.exec  # type: ignore[attr-defined]
        else:
            dataclasses.exec = saved  # type: ignore[attr-defined]


def behaviour(cls: Any) -> list[Any]:
    """What a user sees of ``cls``: its instances' fields, repr, equality, hash and frozenness."""
    a, b = cls("home"), cls("home", (0.5, -1.0), ("x",), 2.0, ["seen"])
    seen: list[Any] = [dataclasses.astuple(a), dataclasses.astuple(b), repr(a), repr(b)]
    seen += [a == cls("home"), a == b, a != b, hash(cls("home", (1.0,))) == hash(cls("home", (1.0,)))]
    seen += [a.notes is not cls("home").notes, a == cls("home", notes=["other"])]
    seen.append([f.name for f in dataclasses.fields(cls)])
    seen += [str(inspect.signature(cls)), cls.__init__.__annotations__, typing.get_type_hints(cls.__init__)]
    with pytest.raises(dataclasses.FrozenInstanceError) as assigned:
        a.name = "away"
    with pytest.raises(dataclasses.FrozenInstanceError) as deleted:
        del a.q
    seen += [str(assigned.value), str(deleted.value)]
    with pytest.raises(TypeError) as missing:
        cls()
    return [*seen, str(missing.value)]


def test_a_class_made_through_kept_code_behaves_as_pythons_own() -> None:
    own = behaviour(made(builtins.exec))
    kept = KeptCode({})
    assert behaviour(made(kept)) == own
    assert kept.compiled == len(kept.used) == len(kept.stored) >= 5  # __init__, __repr__, __eq__, ...
    again = KeptCode(dict(kept.stored))
    assert behaviour(made(again)) == own
    assert again.compiled == 0 and again.used == kept.used  # every method read, none compiled


def test_the_table_goes_through_its_file_and_a_bad_file_is_ignored(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "code.marshal"
    monkeypatch.setattr(dataclass_code, "code_file", lambda: path)
    monkeypatch.setattr(dataclasses, "exec", builtins.exec, raising=False)  # undone after the test
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    kept = reuse_dataclass_code()
    assert reuse_dataclass_code() is kept  # one table a process
    made(kept)
    keep_dataclass_code()
    assert read_stored(path) == kept.stored
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~current_umask()  # as Python's bytecode
    good = path.read_bytes()
    magic = importlib.util.MAGIC_NUMBER + dataclass_code.FORMAT
    older = importlib.util.MAGIC_NUMBER + b"dataclass code 1\n" + good[len(magic) :]  # another format
    for bad in (b"", good[: len(good) // 2], b"\0\0\0\0" + good[4:], older, magic + marshal.dumps([1, 2])):
        path.write_bytes(bad)
        assert read_stored(path) == {}
    path.write_bytes(magic + marshal.dumps({"def f(): pass": b"not code", "x": 3}))
    broken = KeptCode(read_stored(path))
    assert set(broken.stored) == {"def f(): pass"}
    names: dict[str, Any] = {}
    broken("def f(): return 7", names)
    broken("def f(): pass", names)  # stored, but not code: compiled again
    assert broken.compiled == 2 and names["f"]() is None


def test_nothing_is_written_where_python_writes_no_bytecode_or_nothing_was_compiled(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "code.marshal"
    monkeypatch.setattr(dataclass_code, "code_file", lambda: path)
    kept = KeptCode({})
    monkeypatch.setattr(dataclasses, "exec", kept, raising=False)
    made(kept)
    monkeypatch.setattr(sys, "dont_write_bytecode", True)
    keep_dataclass_code()
    assert not path.exists()
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    monkeypatch.setattr(dataclasses, "exec", KeptCode(dict(kept.stored)), raising=False)
    keep_dataclass_code()  # everything read, nothing learned
    assert not path.exists()


def test_a_full_table_keeps_only_what_the_process_used(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "code.marshal"
    monkeypatch.setattr(dataclass_code, "code_file", lambda: path)
    monkeypatch.setattr(dataclass_code, "MOST_TEXTS", 3)
    old = {f"x = {i}": marshal.dumps(compile(f"x = {i}", "<string>", "exec")) for i in range(3)}
    kept = KeptCode(dict(old))
    monkeypatch.setattr(dataclasses, "exec", kept, raising=False)
    names: dict[str, Any] = {}
    kept("x = 1", names)
    kept("x = 9", names)
    monkeypatch.setattr(sys, "dont_write_bytecode", False)
    keep_dataclass_code()
    assert sorted(read_stored(path)) == ["x = 1", "x = 9"]


def current_umask() -> int:
    """The process's file mode mask."""
    mask = os.umask(0)
    os.umask(mask)
    return mask


@pytest.mark.slow
def test_a_new_command_process_compiles_none_of_the_planners_dataclasses(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPYCACHEPREFIX": str(tmp_path), "PYTHONDONTWRITEBYTECODE": "1"}
    run = [sys.executable, "-m", "planning.cli.dataclass_code"]
    built = subprocess.run(run, capture_output=True, text=True, check=True, cwd=ROOT, env=env, timeout=300)
    assert "dataclass methods kept" in built.stdout and not built.stderr
    (path,) = tmp_path.rglob("dataclass_code.*.marshal")
    stale = {**read_stored(path), "x = 1": marshal.dumps(compile("x = 1", "<string>", "exec"))}
    path.write_bytes(importlib.util.MAGIC_NUMBER + dataclass_code.FORMAT + marshal.dumps(stale))
    again = subprocess.run(run, capture_output=True, text=True, check=True, cwd=ROOT, env=env, timeout=300)
    assert "(0 compiled now)" in again.stdout and set(read_stored(path)) == set(stale) - {"x = 1"}
    probe = (
        "import dataclasses\n"
        "from planning.cli.process import start_process\n"
        "start_process()\n"
        "import planning.pipeline.planner, planning.io.scene_file, planning.io.outputs\n"
        "print(dataclasses.exec.compiled, len(dataclasses.exec.used))\n"
    )
    command = [sys.executable, "-c", probe]
    done = subprocess.run(command, capture_output=True, text=True, check=True, cwd=ROOT, env=env, timeout=300)
    compiled, used = map(int, done.stdout.split())
    assert compiled == 0 and used > 100
