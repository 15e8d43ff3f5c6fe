"""``planning.io.report``: the words a person reads of a plan."""

from __future__ import annotations

import math

import pytest

from planning.io.report import clearance_text, markdown_table


@pytest.mark.parametrize("clearance_m", [0.0, 0.19344, -0.0123, 12.5])
def test_a_finite_clearance_reads_in_metres_to_a_tenth_of_a_millimetre(clearance_m: float) -> None:
    text = clearance_text(clearance_m)
    assert text.endswith(" m") and float(text.removesuffix(" m")) == pytest.approx(clearance_m, abs=5e-5)


def test_an_unbounded_clearance_says_there_is_no_obstacle() -> None:
    assert clearance_text(math.inf) == "unbounded, no obstacle"


def test_a_markdown_table_has_a_header_a_rule_and_a_row_each() -> None:
    lines = markdown_table([("a", "1"), ("b", "2")], ("name", "value")).splitlines()
    assert lines[:2] == ["| name | value |", "|---|---|"] and len(lines) == 4
