"""The compiled methods of the command's dataclasses, kept beside its bytecode: a new process compiles none.

Python writes each dataclass's ``__init__``, ``__repr__``, ``__eq__``, ``__hash__``,
``__setattr__`` and ``__delattr__`` as source text when the class is made, and compiles that
text: about half a millisecond a class, some fifty milliseconds of the hundred-odd classes
that a ``cpr-plan plan`` imports (docs/tuning.md, The dataclasses' methods kept compiled).
Python keeps the modules' own bytecode in ``__pycache__`` but not this code. The text depends
only on a class's fields and options, and the same text compiled by the same Python is the same
code. So, in a process that runs one command:

- :func:`reuse_dataclass_code` points :mod:`dataclasses`'s ``exec`` at :class:`KeptCode`, which
  compiles each text once and reads the code compiled before from this package's
  ``__pycache__`` (the file named by Python's cache tag, headed by its bytecode's magic number and
  :data:`FORMAT`);
- :func:`keep_dataclass_code`, at the process's end, writes the table back where it learned a
  text: whole, to a temporary file renamed in place, and not where Python writes no bytecode
  (``PYTHONDONTWRITEBYTECODE``) or cannot write the folder, as Python treats its own.
  ``python -m planning.cli.dataclass_code`` (``make bytecode``, beside ``compileall``) writes it
  whatever that setting, from every module of the two packages (:func:`build`).

The classes are the same: their methods run the code Python would have compiled from the same
text, with the same globals. A library caller's process keeps Python's own behaviour.
"""

from __future__ import annotations

import builtins
import contextlib
import dataclasses
import importlib
import importlib.util
import marshal
import pkgutil
import sys
from pathlib import Path
from types import CodeType
from typing import Any

MOST_TEXTS = 4096
"""The most texts the file keeps; beyond, it keeps only those of the process writing it."""
FORMAT = b"dataclass code 2\n"
"""What follows Python's magic number in the file: a file of another format is not read."""


def code_file() -> Path:
    """The file of kept code: this package's ``__pycache__`` (or ``sys.pycache_prefix``), by cache tag."""
    bytecode = Path(importlib.util.cache_from_source(__file__))
    return bytecode.with_name(f"dataclass_code.{sys.implementation.cache_tag}.marshal")


class KeptCode:
    """``exec`` for :mod:`dataclasses`: a text's code compiled once, or read from :func:`code_file`.

    Attributes:
        stored: each text's code, marshalled: read from the file, and what this process compiled.
        used: the texts this process made classes from.
        compiled: how many texts this process compiled (those not in the file).
    """

    def __init__(self, stored: dict[str, bytes]) -> None:
        self.stored, self.used, self.compiled = stored, set[str](), 0

    def __call__(self, source: Any, globals: Any = None, locals: Any = None) -> None:
        """Run ``source`` as :func:`exec` would, its code compiled once a text."""
        if isinstance(source, str):
            code = self._code(source)
            self.used.add(source)
            source = code
        builtins.exec(source, globals, locals)

    def _code(self, text: str) -> CodeType:
        """The code of ``text``: the stored one's, else compiled now (and stored)."""
        stored = self.stored.get(text)
        if stored is not None:
            with contextlib.suppress(EOFError, ValueError, TypeError):
                code = marshal.loads(stored)
                if isinstance(code, CodeType):
                    return code
        # as `exec` compiles the text for dataclasses, whose module has no `from __future__`
        # import: this module's `annotations` would make the methods' annotations strings
        code = compile(text, "<string>", "exec", dont_inherit=True)
        self.stored[text] = marshal.dumps(code)
        self.compiled += 1
        return code

    def used_stored(self) -> dict[str, bytes]:
        """The stored code of the texts this process used."""
        return {text: self.stored[text] for text in self.used}


def read_stored(path: Path) -> dict[str, bytes]:
    """The table in ``path``; empty where there is none, or it is another Python's or unreadable.

    Each code stays marshalled until a class needs it: a process needs some of them.
    """
    try:
        data = path.read_bytes()
    except OSError:
        return {}
    magic = _header()
    if not data.startswith(magic):
        return {}
    try:
        table = marshal.loads(data[len(magic) :])
    except (EOFError, ValueError, TypeError):
        return {}
    if not isinstance(table, dict):
        return {}
    return {k: v for k, v in table.items() if isinstance(k, str) and isinstance(v, bytes)}


def reuse_dataclass_code() -> KeptCode:
    """Make :mod:`dataclasses` compile through a :class:`KeptCode` read from :func:`code_file`."""
    current = getattr(dataclasses, "exec", None)
    if isinstance(current, KeptCode):
        return current
    kept = KeptCode(read_stored(code_file()))
    dataclasses.exec = kept  # type: ignore[attr-defined]  # a module global before the builtin
    return kept


def keep_dataclass_code() -> None:
    """Write the table back where this process compiled a text (module docstring); else nothing."""
    kept = getattr(dataclasses, "exec", None)
    if not isinstance(kept, KeptCode) or kept.compiled == 0 or sys.dont_write_bytecode:
        return
    write_stored(code_file(), kept.stored if len(kept.stored) <= MOST_TEXTS else kept.used_stored())


def write_stored(path: Path, table: dict[str, bytes]) -> None:
    """Write ``table`` to ``path`` whole; a folder that cannot be written is no error.

    :func:`~cpr_kin.common.disk_cache.saved_whole`: a temporary file of the writer's own,
    renamed, with the mode Python's own bytecode gets.
    """
    from cpr_kin.common.disk_cache import saved_whole  # it brings NumPy: imported only to write

    saved_whole(path, lambda partial: partial.write_bytes(_header() + marshal.dumps(table)))


def _header() -> bytes:
    """The file's first bytes: Python's bytecode magic number and :data:`FORMAT`."""
    return importlib.util.MAGIC_NUMBER + FORMAT


def build(packages: tuple[str, ...] = ("cpr_kin", "planning")) -> KeptCode:
    """Compile the methods of every dataclass in ``packages``' modules and keep them (``make bytecode``).

    Written whatever ``PYTHONDONTWRITEBYTECODE`` says, as ``compileall`` writes, and only what
    the modules make now. A module that needs what is not installed (an optional extra) is
    left out.
    """
    kept = reuse_dataclass_code()
    for name in packages:
        package = importlib.import_module(name)
        for module in pkgutil.walk_packages(package.__path__, f"{name}."):
            if not module.name.endswith("__main__"):
                with contextlib.suppress(ImportError):
                    importlib.import_module(module.name)
    if kept.compiled or len(kept.stored) > len(kept.used):  # new texts, or texts no module writes now
        write_stored(code_file(), kept.used_stored())
    return kept


if __name__ == "__main__":
    made = build()
    print(f"{len(made.used)} dataclass methods kept in {code_file()} ({made.compiled} compiled now)")
