"""JSON text for files people read: nested structure indented, flat lists on one line.

``json.dumps(document, indent=1)`` puts every number of a trajectory on a line of its own
(thousands of lines for a few segments), and any ``indent`` makes :mod:`json` fall back to
its pure-Python encoder. :func:`dumps` indents objects and lists that hold objects or
lists, and writes every other value (numbers, strings, lists of them) with the C encoder on
one line: a waypoint or a row of spline coefficients is one line, and the text is written
faster. It parses to the same document as
:func:`json.dumps` gives, float for float (both print ``repr``), but for one thing: JSON has no
NaN or infinity (RFC 8259; :mod:`json` would write ``NaN`` and ``Infinity``, which strict
parsers refuse), so a number that is not finite is written ``null``: the certified clearance
of a scene without obstacles, a figure that was not measured.
"""

from __future__ import annotations

import json
import math
from typing import Any

_strict = json.JSONEncoder(separators=(", ", ": "), allow_nan=False).encode
"""The C encoder, with the spaces the indented layout uses; it refuses NaN and infinities."""


def dumps(document: Any, indent: int = 1) -> str:
    """``document`` as JSON text, nested containers indented by ``indent`` spaces per level.

    Args:
        document: plain JSON types (dict with string keys, list, str, int, float, bool, None).
        indent: spaces per nesting level, >= 0.

    Raises:
        TypeError: a value JSON cannot hold, as :func:`json.dumps` does, or a key that is
            not a string. A number that is not finite is no error: it is written ``null``.
    """
    return _layout(document, indent, 0)


def _flat(value: Any) -> str:
    """``value`` on one line by the C encoder, its non-finite numbers as ``null``."""
    try:
        return _strict(value)
    except ValueError as error:
        if "not JSON compliant" not in str(error):  # not a NaN or an infinity (a circular list)
            raise
        return _strict(_finite(value))


def _finite(value: Any) -> Any:
    """``value`` with each number that is not finite replaced by ``None``."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: _finite(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(item) for item in value]
    return value


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
