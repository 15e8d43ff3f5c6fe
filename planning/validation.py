"""Checks of settings values that raise one short :class:`~planning.errors.PlanningError`.

Every message names the setting, shows the value (shortened: a hostile value must not
flood the terminal) and states what is allowed. Booleans are not numbers here, although
Python counts ``True`` as 1: ``fireflies = True`` is a mistake, not a population of one.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from numbers import Real
from typing import Any, get_args

import numpy as np
from pydantic import BaseModel, ValidationError

from cpr_kin.common.names import cut
from cpr_kin.common.names import shown as shown  # re-exported: the search's settings use it, not cpr_kin
from planning.errors import PlanningError


def _is_number(value: Any) -> bool:
    return isinstance(value, Real | np.floating | np.integer) and not isinstance(value, bool | np.bool_)


def instance_of(name: str, value: Any, kind: type | tuple[type, ...], hint: str) -> None:
    """Refuse a ``value`` that is not a ``kind`` (a str where a Scene belongs), naming how to make one.

    ``hint``: where such a value comes from, e.g. ``"planning.Scene (load_scene, paper_scene)"``.
    """
    if not isinstance(value, kind):
        raise PlanningError(f"{name} is a {type(value).__name__}; give a {hint}")


def boolean(name: str, value: Any) -> bool:
    """``value`` if it is ``True`` or ``False``; else a :class:`PlanningError`."""
    if not isinstance(value, bool):
        raise PlanningError(f"{name} = {shown(value)} must be True or False")
    return value


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


MAX_PROBLEMS = 3
"""Most problems one message lists (the rest are counted)."""
MAX_PROBLEM_CHARS = 200
"""Most characters of the problems one message lists: a further problem that would pass it
is counted instead (the first is always listed), so that a message stays one short line
whatever the values."""

Location = tuple[int | str, ...]


def field_path(location: Location, hidden: Sequence[str] = ()) -> str:
    """``obstacles[1].size[2]`` for pydantic's location ``("obstacles", 1, "size", 2)``.

    Parts in ``hidden`` (a tagged union's branch names) are not keys of the file and are left
    out, but never the part right after one: a branch is a model, so what follows its name is
    one of its keys, though it be spelt like a branch (``("obstacles", 0, "mesh", "mesh")`` is
    ``obstacles[0].mesh``). A hostile key is shortened like a value.
    """
    text = ""
    after_branch = False
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
            after_branch = False
        elif part in hidden and not after_branch:
            after_branch = True
        else:
            key = cut(str(part))
            text += f".{key}" if text else key
            after_branch = False
    return text or "(top level)"


def model_within(root: type[BaseModel]) -> Callable[[Location], type[BaseModel] | None]:
    """The ``model_at`` of :func:`describe_validation` for nested models without unions of models.

    Follows a location's keys through ``root``'s fields (a field of a model, or a list,
    tuple, dict or optional of one) to the model that owns its last key.
    """

    def model_at(location: Location) -> type[BaseModel] | None:
        model: type[BaseModel] = root
        for part in location[:-1]:
            if isinstance(part, int):
                continue  # an item of a list the last field held
            field = model.model_fields.get(str(part))
            found = _model_in(field.annotation) if field is not None else None
            if found is None:
                return None
            model = found
        return model

    return model_at


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The model an annotation holds: itself, or the one model among its arguments."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    models = {m for m in map(_model_in, get_args(annotation)) if m is not None}
    return models.pop() if len(models) == 1 else None


def describe_validation(
    error: ValidationError,
    model_at: Callable[[Location], type[BaseModel] | None] = lambda _: None,
    hidden: Sequence[str] = (),
    tag: tuple[str, Sequence[str]] | None = None,
) -> str:
    """One line naming the first :data:`MAX_PROBLEMS` problems of a pydantic validation.

    Fewer when they would take more than :data:`MAX_PROBLEM_CHARS`; the others are counted.

    Args:
        error: the validation error.
        model_at: the model owning a location, to list the keys allowed where one is unknown.
        hidden: location parts that are not keys of the file (see :func:`field_path`).
        tag: a tagged union's tag and its allowed values, e.g. ``("shape", ("box", ...))``.
    """
    problems = []
    for item in error.errors():
        location = tuple(item["loc"])
        where = field_path(location, hidden)
        value = item.get("input")
        if item["type"] == "extra_forbidden":
            model = model_at(location)
            allowed = ", ".join(model.model_fields) if model is not None else ""
            problems.append(f"{where}: unknown key; allowed here: {allowed}")
        elif item["type"] == "missing":
            problems.append(f"{where}: required key is missing")
        elif item["type"] in ("union_tag_invalid", "union_tag_not_found") and tag and isinstance(value, dict):
            expected = str(item.get("ctx", {}).get("expected_tags", "")).replace("'", "")
            key, allowed = tag[0], expected or ", ".join(tag[1])  # this union's tags, if pydantic says
            problems.append(
                f"{where}.{key} = {shown(value.get(key))}: unknown or missing {key}; allowed: {allowed}"
            )
        else:
            message = item["msg"].removeprefix("Value error, ")
            if isinstance(value, dict):  # a block (a model's input): its keys tell more than its repr
                problems.append(f"{where}: {message}")
            elif item["type"] in ("too_long", "too_short") and isinstance(value, list | tuple):
                context = item.get("ctx", {})  # its count and the bound, not a cut repr
                if item["type"] == "too_long":
                    bound = f"at most {context.get('max_length')} allowed"
                else:
                    bound = f"needs at least {context.get('min_length')}"
                problems.append(f"{where}: {len(value)} item{'' if len(value) == 1 else 's'}; {bound}")
            else:
                problems.append(f"{where} = {shown(value)}: {message}")
    listed = problems[:1]
    for problem in problems[1:MAX_PROBLEMS]:
        if len("; ".join([*listed, problem])) > MAX_PROBLEM_CHARS:
            break
        listed.append(problem)
    more = len(problems) - len(listed)
    return "; ".join(listed) + (f"; and {more} more" if more > 0 else "")


QUATERNION_NORM_TOLERANCE = 1e-3
"""How far a quaternion's norm may be from 1 and still be normalised (rounding of printed
values); beyond it the numbers are not a rotation and are refused (as MoveIt's orientation
constraints warn beyond it)."""


def unit_quaternion(xyzw: Sequence[float]) -> tuple[float, float, float, float]:
    """``xyzw`` normalised, if its norm is within :data:`QUATERNION_NORM_TOLERANCE` of 1.

    One rule for every quaternion a file gives: rounding is normalised away, a quaternion
    that is no rotation (a norm of 0, or far from 1) is a ``ValueError`` naming the norm
    (pydantic prefixes the field and its value).
    """
    values = np.asarray(xyzw, dtype=float)
    norm = math.hypot(*values)  # no overflow warning for 1e308
    if not abs(norm - 1.0) <= QUATERNION_NORM_TOLERANCE:
        meant = [round(float(v), 6) for v in values / norm] if 0 < norm < math.inf else []
        hint = f"; did you mean {meant}?" if any(meant) else ""
        raise ValueError(
            f"has norm {norm:.6g}; a rotation's quaternion [x, y, z, w] has norm 1 "
            f"(within {QUATERNION_NORM_TOLERANCE:g}){hint}"
        )
    x, y, z, w = (float(v) for v in values / norm)
    return x, y, z, w
