"""Checks of settings values that raise one short :class:`~planning.errors.PlanningError`.

Every message names the setting, shows the value (shortened: a hostile value must not
flood the terminal) and states what is allowed. Booleans are not numbers here, although
Python counts ``True`` as 1: ``fireflies = True`` is a mistake, not a population of one.
"""

from __future__ import annotations

import math
from numbers import Real
from typing import Any

import numpy as np

from planning.errors import PlanningError

MAX_VALUE_CHARS = 40
"""Longest rendering of a value in a message; longer ones are cut with an ellipsis."""


def shown(value: Any) -> str:
    """``repr(value)``, cut to :data:`MAX_VALUE_CHARS` characters."""
    text = repr(value)
    return text if len(text) <= MAX_VALUE_CHARS else text[: MAX_VALUE_CHARS - 3] + "..."


def _is_number(value: Any) -> bool:
    return isinstance(value, Real | np.floating | np.integer) and not isinstance(value, bool | np.bool_)


def integer_in(name: str, value: Any, low: int, high: int) -> int:
    """``value`` as an ``int`` if it is an integer in ``[low, high]``; else a :class:`PlanningError`."""
    if (
        isinstance(value, bool | np.bool_)
        or not isinstance(value, int | np.integer)
        or not low <= value <= high
    ):
        raise PlanningError(f"{name} = {shown(value)} must be an integer in [{low}, {high}]")
    return int(value)


def number_in(
    name: str, value: Any, low: float, high: float, unit: str = "", low_open: bool = False
) -> float:
    """``value`` as a ``float`` if it is a finite number in ``[low, high]`` (``(low, high]``).

    Args:
        name: the setting's name, as the user wrote it.
        value: the value to check.
        low: smallest value allowed.
        high: largest value allowed.
        unit: the unit shown after the bounds, e.g. ``"m"``.
        low_open: ``low`` itself is not allowed.
    """
    number = _is_number(value)
    if not (number and math.isfinite(value) and low <= value <= high and not (low_open and value == low)):
        bracket = "(" if low_open else "["
        suffix = f" {unit}" if unit else ""
        given = f"{shown(value)}{suffix if number else ''}"
        raise PlanningError(f"{name} = {given} must be a number in {bracket}{low:g}, {high:g}]{suffix}")
    return float(value)
