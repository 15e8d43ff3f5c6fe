r"""Names and text from a user's files, made safe to print: no control or bidirectional characters.

A name (a joint, link or collision element of a URDF, an obstacle, a scene) reaches
terminals, reports and CSV files. A control character (``\x1b[2J`` clears a terminal) or a
bidirectional override (U+202E turns ``exe.txt`` around) would make what is printed lie
about what is there, so a name holding one is refused (:func:`unprintable`), and text that
cannot be refused (a file's own path) is printed with such characters escaped
(:func:`escaped`).

Refused: Unicode's control (Cc), format (Cf: the bidirectional controls, zero-width
joiners), surrogate (Cs), private-use (Co) and unassigned (Cn) characters, and the line and
paragraph separators (Zl, Zp).
"""

from __future__ import annotations

import unicodedata
from collections import Counter
from collections.abc import Sequence

UNPRINTABLE_CATEGORIES = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})
"""Unicode general categories that are never printed as they are."""
MAX_SHOWN_CHARS = 40
"""Longest rendering of a value in a message: a hostile value must not flood the terminal."""


MAX_LINE_CHARS = 1000
"""Longest message line printed or written (the CLI's errors, a batch summary's row): a hostile
input must not flood a terminal or a file. Each value a message shows is cut where it is shown
(:func:`shown`); what is left long is a file's path, which may take a few hundred characters
before the message says what is wrong."""


def one_line(text: str, limit: int = MAX_LINE_CHARS) -> str:
    """``text`` as one line: whitespace runs as one space, :func:`escaped`, cut to ``limit`` characters."""
    return cut(escaped(" ".join(text.split())), limit)


def cut(text: str, limit: int = MAX_SHOWN_CHARS) -> str:
    """``text``, cut to ``limit`` characters with an ellipsis."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def shown(value: object, limit: int = MAX_SHOWN_CHARS) -> str:
    """``repr(value)``, cut to ``limit`` characters, as a message shows a value."""
    return cut(repr(value), limit)


def _unprintable(character: str) -> bool:
    return unicodedata.category(character) in UNPRINTABLE_CATEGORIES


def describe(character: str) -> str:
    """``U+202E (RIGHT-TO-LEFT OVERRIDE)``: a character as a message names it."""
    name = unicodedata.name(character, "")
    return f"U+{ord(character):04X}" + (f" ({name})" if name else "")


def unprintable(text: str) -> str | None:
    """The first control or bidirectional character of ``text``, described, or ``None``."""
    for character in text:
        if _unprintable(character):
            return describe(character)
    return None


def escaped(text: str) -> str:
    r"""``text`` with every character :func:`unprintable` refuses written as ``\u202e`` (``\n`` stays)."""
    if not any(_unprintable(c) for c in text):
        return text
    return "".join(
        c if c == "\n" or not _unprintable(c) else c.encode("unicode_escape").decode("ascii") for c in text
    )


def repeated(names: Sequence[str]) -> list[str]:
    """The names that ``names`` gives more than once, sorted (a duplicate joint, obstacle, file)."""
    counts = Counter(names)
    return sorted(name for name, count in counts.items() if count > 1)


def listed(names: Sequence[str], most: int) -> str:
    """``names`` quoted for a message, the first ``most`` of them, the rest counted.

    ``listed(["a", "b", "c"], 2)`` is ``'a', 'b' and 1 more``.
    """
    quoted = ", ".join(f"'{escaped(name)}'" for name in names[:most])
    return quoted + (f" and {len(names) - most} more" if len(names) > most else "")
