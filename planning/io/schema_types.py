"""The value types the file schemas share: bounded numbers, points, printable names, file paths."""

from typing import Annotated, Any

from pydantic import AfterValidator, BaseModel, ConfigDict, Discriminator, Field

from cpr_kin.common.names import unprintable
from cpr_kin.shapes.obstacle_ranges import MAX_ANGLE_RAD, MAX_COORDINATE_M, MAX_NAME_CHARS, SIZE_RANGE_M
from planning.pipeline.scene import SPLINE_A_RANGE


def between(low: float, high: float) -> Any:
    """A finite number in ``[low, high]``."""
    return Field(ge=low, le=high, allow_inf_nan=False)


def empty_list() -> list[Any]:
    """A new empty list: the default factory of the schemas' list fields.

    pydantic reads a default factory's signature (whether it takes the data validated so far).
    The builtin ``list``'s is text that Python parses with ``tokenize``, whose pattern every new
    ``cpr-plan`` process would compile for it (docs/tuning.md, A process that runs one command).
    A function's signature is read from its code.
    """
    return []


def printable(text: str) -> str:
    """``text`` if it holds no control or bidirectional character (a ``ValueError`` otherwise)."""
    character = unprintable(text)
    if character is not None:
        raise ValueError(f"holds {character}; names must be printable text")
    return text


Coordinate = Annotated[float, between(-MAX_COORDINATE_M, MAX_COORDINATE_M)]
Angle = Annotated[float, between(-MAX_ANGLE_RAD, MAX_ANGLE_RAD)]
Size = Annotated[float, between(*SIZE_RANGE_M)]
Point = Annotated[list[Coordinate], Field(min_length=3, max_length=3)]
Turn = Annotated[list[Angle], Field(min_length=3, max_length=3)]
Name = Annotated[str, Field(min_length=1, max_length=MAX_NAME_CHARS), AfterValidator(printable)]
"""A name of 1-100 printable characters (no control or bidirectional ones)."""
FilePath = Annotated[str, Field(min_length=1, max_length=4096)]
Weight = Annotated[float, between(0.0, SPLINE_A_RANGE[1])]


MAPPING_TAG = "mapping"
"""The branch of a :data:`BY_KIND` union a mapping takes (not a key of the file)."""
OTHER_TAG = "other"
"""The branch of a :data:`BY_KIND` union any other value takes (not a key of the file)."""
UNION_TAGS = (MAPPING_TAG, OTHER_TAG)
"""The location parts of those unions' branches, left out of the field paths of messages."""


def _kind(value: Any) -> str:
    return MAPPING_TAG if isinstance(value, dict) else OTHER_TAG


BY_KIND = Discriminator(_kind)
"""Chooses a union's branch by the value's kind: ``Annotated[Annotated[X, Tag(OTHER_TAG)] |
Annotated[Y, Tag(MAPPING_TAG)], BY_KIND]`` is ``Y`` for a mapping, else ``X``. A plain union
would report each failed branch ("should be a valid list; should be a valid dictionary"); this
one reports the branch the user meant."""


class Strict(BaseModel):
    """A schema block: unknown keys refused, a number must be a number (not true, not "0.1").

    Its validator is built where it is first used (``defer_build``): a scene file's model then
    builds the blocks it holds once, inside its own, rather than each block's at its import too.
    The modules of the models give pydantic their annotations as objects, not as text (no
    ``from __future__ import annotations``), which it would evaluate field by field in every
    process (``tests/test_scene_file.py``).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, defer_build=True)
