"""JSON text for files people read: nested structure indented, flat lists on one line.

``json.dumps(document, indent=1)`` puts every number of a trajectory on a line of its own
(thousands of lines for a few segments), and any ``indent`` makes :mod:`json` fall back to
its pure-Python encoder. :func:`dumps` indents objects and lists that hold objects or
lists, and writes every other value (numbers, strings, lists of them) with the C encoder on
one line: a waypoint or a row of spline coefficients is one line, and the text is written
faster. It parses to the same document as
:func:`json.dumps` gives, float for float (both print ``repr``).
"""

from __future__ import annotations

import json
from typing import Any

_flat = json.JSONEncoder(separators=(", ", ": ")).encode
"""The C encoder, with the spaces the indented layout uses."""


def dumps(document: Any, indent: int = 1) -> str:
    """``document`` as JSON text, nested containers indented by ``indent`` spaces per level.

    Args:
        document: plain JSON types (dict with string keys, list, str, int, float, bool, None).
        indent: spaces per nesting level, >= 0.

    Raises:
        TypeError: a value JSON cannot hold, as :func:`json.dumps` does, or a key that is
            not a string.
    """
    return _layout(document, indent, 0)


def _nested(value: Any) -> bool:
    """Whether ``value`` is a non-empty object, or a list holding an object or a list."""
    if isinstance(value, dict):
        return bool(value)
    return isinstance(value, list) and any(isinstance(item, (dict, list)) for item in value)


def _layout(value: Any, indent: int, depth: int) -> str:
    if not _nested(value):
        return _flat(value)
    inner = "\n" + " " * (indent * (depth + 1))
    if isinstance(value, dict):
        for key in value:
            if not isinstance(key, str):
                raise TypeError(f"JSON object keys must be strings, not {type(key).__name__} {key!r}")
        items = [f"{_flat(key)}: {_layout(item, indent, depth + 1)}" for key, item in value.items()]
        opening, closing = "{", "}"
    else:
        items = [_layout(item, indent, depth + 1) for item in value]
        opening, closing = "[", "]"
    return opening + inner + ("," + inner).join(items) + "\n" + " " * (indent * depth) + closing
