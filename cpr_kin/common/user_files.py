"""Reading files that a user (or an attacker) wrote: bounded, and YAML unambiguous, never recursive.

:func:`read_bytes` and :func:`read_text` read a regular file of bounded size (a folder, a
device such as ``/dev/zero`` or a file too large is refused before anything is read into
memory beyond the bound). :func:`load_yaml` parses YAML safely. PyYAML's safe loader is
safe from code execution, not from the rest:

- *aliases* expand without limit: 517 bytes of nested aliases make gigabytes ("billion
  laughs");
- deep nesting makes its composer recurse: a RecursionError at 2,000 levels, a segfault of
  libyaml's loader at 100,000;
- a *duplicate key* silently replaces the first: a second ``obstacles: []`` drops every
  obstacle.

:func:`load_yaml` reads at most ``max_bytes`` of a regular file, then walks the parser's
event stream (iterative, in C) refusing anchors, aliases, nesting deeper than
:data:`MAX_DEPTH` and more than :data:`MAX_NODES` nodes, and only then builds the document
with a loader that refuses duplicate keys. Every refusal is a :class:`UserFileError` naming the
line. Numbers in exponent form without a dot (``1e6``) are floats, as in YAML 1.2.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path
from typing import Any

import yaml

from cpr_kin.common.errors import CprKinError
from cpr_kin.common.names import cut, shown

YAML_SUFFIXES = (".yaml", ".yml")
"""What a YAML file's name ends with (in any case: ``SCENE.YAML`` is one)."""
MAX_DEPTH = 16
"""Deepest nesting of sequences and mappings (a scene file nests 4 levels)."""
MAX_NODES = 100_000
"""Most nodes (scalars, sequences, mappings) in one file."""

_BASE = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml's parser, in C, where installed


class UserFileError(CprKinError):
    """A user's file is missing, not a regular file, too large, not UTF-8, or malformed YAML."""


class StrictLoader(_BASE):  # type: ignore[misc, valid-type]
    """The safe loader with duplicate keys refused and YAML 1.2's exponent floats."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        """A mapping whose keys are hashable and each given once."""
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                first = seen.get(key)
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    None, None, "a key must be a plain value, not a list or mapping", key_node.start_mark
                ) from None
            if first is not None:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"duplicate key {shown(key)} (first given at line {first})",
                    key_node.start_mark,
                )
            seen[key] = key_node.start_mark.line + 1
        return dict(super().construct_mapping(node, deep=deep))


StrictLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def is_yaml_name(path: Path | str) -> bool:
    """Whether ``path``'s name ends with one of :data:`YAML_SUFFIXES`, in any case."""
    return Path(path).suffix.lower() in YAML_SUFFIXES


def _line(event: Any) -> str:
    mark = getattr(event, "start_mark", None)
    return f"line {mark.line + 1}" if mark is not None else "somewhere"


def _scan(text: str, source: str) -> None:
    """Walk the event stream; raise at the first anchor, alias, too deep or too large part."""
    depth = nodes = 0
    for event in yaml.parse(text, Loader=_BASE):
        if isinstance(event, yaml.AliasEvent):
            raise UserFileError(
                f"{source}: {_line(event)}: aliases (*name) are not allowed; write the value out"
            )
        if getattr(event, "anchor", None) is not None:
            raise UserFileError(
                f"{source}: {_line(event)}: anchors (&name) are not allowed; write the value out"
            )
        if isinstance(event, yaml.ScalarEvent | yaml.SequenceStartEvent | yaml.MappingStartEvent):
            nodes += 1
            if nodes > MAX_NODES:
                raise UserFileError(
                    f"{source}: more than {MAX_NODES} values (numbers, strings, lists, mappings); "
                    f"at most {MAX_NODES} are read"
                )
        if isinstance(event, yaml.SequenceStartEvent | yaml.MappingStartEvent):
            depth += 1
            if depth > MAX_DEPTH:
                raise UserFileError(f"{source}: {_line(event)}: nested more than {MAX_DEPTH} levels deep")
        elif isinstance(event, yaml.SequenceEndEvent | yaml.MappingEndEvent):
            depth -= 1


def read_bytes(path: Path, max_bytes: int, what: str) -> bytes:
    """The content of the regular file ``path``, at most ``max_bytes`` long.

    Raises:
        UserFileError: missing, not a regular file, or larger than ``max_bytes``.
    """
    if not path.exists():
        raise UserFileError(f"{what} '{path}' does not exist")
    if not path.is_file():
        raise UserFileError(f"{what} '{path}' is not a regular file (a folder or a device)")
    try:
        with path.open("rb") as stream:
            data = stream.read(max_bytes + 1)  # st_size can lie (a pipe, /proc): read, then count
    except OSError as exc:
        raise UserFileError(f"cannot read {what} '{path}': {exc.strerror or exc}") from None
    if len(data) > max_bytes:
        raise UserFileError(f"{what} '{path}' is larger than {max_bytes} bytes")
    return data


def read_text(path: Path, max_bytes: int, what: str) -> str:
    """The UTF-8 text of the regular file ``path``, at most ``max_bytes`` long.

    Raises:
        UserFileError: missing, not a regular file, larger than ``max_bytes``, or not UTF-8.
    """
    data = read_bytes(path, max_bytes, what)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        byte = f"byte {exc.start} is 0x{data[exc.start]:02x}"
        raise UserFileError(f"{what} '{path}' is not UTF-8 text ({byte})") from None


def load_yaml(path: Path, max_bytes: int, what: str = "YAML file") -> Any:
    """The parsed document of the YAML file ``path``; see the module docstring for what it refuses.

    Args:
        path: the file.
        max_bytes: largest file accepted [bytes].
        what: what the file is, for messages (e.g. ``"scene file"``).

    Raises:
        UserFileError: the file is unreadable, too large, not YAML, or refused; one line.
    """
    text = read_text(Path(path), max_bytes, what)
    source = f"{what} '{path}'"
    # the scan raises UserFileError itself (a ValueError, not a constructor's); a syntax error
    # it meets is reported by the load below, with its line
    with contextlib.suppress(yaml.YAMLError):
        _scan(text, source)
    try:
        return yaml.load(text, Loader=StrictLoader)
    except RecursionError:  # pragma: no cover - the depth is bounded by the scan
        raise UserFileError(f"{source}: nested too deeply") from None
    except (ValueError, TypeError, IndexError, OverflowError) as exc:  # a constructor's own error
        raise UserFileError(
            f"{source} is not valid YAML: {cut(f'{type(exc).__name__}: {exc}', 120)}"
        ) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or " ".join(str(exc).split())
        raise UserFileError(f"{source} is not valid YAML{where}: {cut(str(problem), 120)}") from None


class _PlainDumper(yaml.SafeDumper):
    """``yaml.SafeDumper`` that writes a value met twice out again instead of as an alias."""

    def ignore_aliases(self, data: Any) -> bool:
        return True


def dump_yaml(document: Any, width: int = 80) -> str:
    """``document`` as YAML that :func:`load_yaml` reads back, keys in their order.

    Lists of scalars in flow style; no anchors or aliases (which it refuses), however often a
    list is shared. ``width``: the preferred line length [characters].
    """
    return yaml.dump(document, Dumper=_PlainDumper, sort_keys=False, default_flow_style=None, width=width)
