"""Argument types for the project's scripts: a bad value is argparse's one line and exit 2.

``parser.add_argument("--scenes", type=integer_at_least(1))`` refuses ``--scenes -3`` with
``argument --scenes: -3 must be an integer >= 1``, before anything runs, where ``type=int``
would let it through to fail later with a traceback (an empty median, a negative seed).
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path


def integer_at_least(low: int) -> Callable[[str], int]:
    """An argparse type: the text as an ``int`` that is at least ``low``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = low - 1
        if value < low:
            raise argparse.ArgumentTypeError(f"{text} must be an integer >= {low}")
        return value

    return parse


def number_above(low: float, unit: str = "") -> Callable[[str], float]:
    """An argparse type: the text as a finite ``float`` greater than ``low`` (``unit``: shown after it)."""
    return _number(low, unit, strict=True)


def number_at_least(low: float, unit: str = "") -> Callable[[str], float]:
    """An argparse type: the text as a finite ``float`` at least ``low`` (``unit``: shown after it)."""
    return _number(low, unit, strict=False)


def _number(low: float, unit: str, strict: bool) -> Callable[[str], float]:
    """The text as a finite ``float`` above ``low`` (``strict``) or at least ``low``."""
    relation = ">" if strict else ">="

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value > low if strict else value >= low)):
            raise argparse.ArgumentTypeError(
                f"{text} must be a number {relation} {low:g}{f' {unit}' if unit else ''}"
            )
        return value

    return parse


def checkout(text: str) -> Path:
    """An argparse type: another checkout of this project to time beside this one, made absolute."""
    path = Path(text)
    if not (path / "planning").is_dir():
        raise argparse.ArgumentTypeError(f"{text} is not a checkout of this project (no planning/ package)")
    return path.resolve()


SEED = integer_at_least(0)
"""A random generator's seed: a non-negative integer."""
COUNT = integer_at_least(1)
"""A count of scenes, runs, problems: a positive integer."""
SECONDS = number_above(0.0, "s")
"""A time [s], > 0."""


def add_package_dirs(parser: argparse.ArgumentParser) -> None:
    """Give ``parser`` ``--package-dir DIR``, repeatable (``args.package_dir``): a scene's ``packages``."""
    parser.add_argument(
        "--package-dir",
        type=Path,
        action="append",
        default=[],
        metavar="DIR",
        help="a folder holding the packages the URDF's package:// meshes name (repeatable)",
    )
