from __future__ import annotations

import pytest

from cpr_kin.common.names import MAX_LINE_CHARS, escaped, listed, one_line, unprintable


@pytest.mark.parametrize(
    ("text", "found"),
    [
        ("crate", None),
        ("Kiste-Ä_01 (links)", None),
        ("evil\u202etxt.exe", "U+202E (RIGHT-TO-LEFT OVERRIDE)"),
        ("clear\x1b[2J", "U+001B"),
        ("zero\u200bwidth", "U+200B (ZERO WIDTH SPACE)"),
        ("line\u2028break", "U+2028 (LINE SEPARATOR)"),
        ("tab\there", "U+0009"),
    ],
)
def test_unprintable_names_the_first_offending_character(text: str, found: str | None) -> None:
    assert unprintable(text) == found


def test_escaped_shows_every_unprintable_character_and_keeps_the_rest() -> None:
    assert escaped("plain text, ünïcode") == "plain text, ünïcode"
    assert escaped("a\u202eb\x1bc\nd") == "a\\u202eb\\x1bc\nd"  # newlines stay: they separate lines
    for text in ("x\u202ey", "\x07bell", "a\u2066b\u2069"):
        assert unprintable(escaped(text)) is None


def test_repeated_names_each_name_given_more_than_once_in_order() -> None:
    from cpr_kin.common.names import repeated

    assert repeated(["b", "a", "b", "c", "a", "b"]) == ["a", "b"]
    assert repeated(["a", "b"]) == [] and repeated([]) == []


def test_one_line_joins_escapes_and_cuts() -> None:
    assert one_line("a  file\n\tis\u202emissing") == "a file is\\u202emissing"
    long = one_line("x " * 2000)
    assert len(long) == MAX_LINE_CHARS and long.endswith("...") and long.startswith("x x")
    assert one_line("short", limit=4) == "s..."


@pytest.mark.parametrize("count", [0, 1, 3, 4, 9])
def test_listed_quotes_the_first_names_and_counts_the_rest(count: int) -> None:
    names = [f"link_{i}" for i in range(count)]
    text = listed(names, 3)
    assert text.count("'") == 2 * min(count, 3)
    assert text.endswith(f" and {count - 3} more") == (count > 3)
    assert "more" not in text or count > 3


def test_listed_escapes_what_a_terminal_would_obey() -> None:
    assert listed(["a\u202eb"], 2) == "'a\\u202eb'"
