"""A MoveIt robot state's joint values as a scene file's: merged, wrapped, and onto their ranges.

A continuous joint's start value is turned into [-pi, pi] rad, its goal value by whole turns to
the nearest of the start's, within the [-2 pi, 2 pi] rad it is planned in: MoveIt plans a
continuous joint the short way round, and so does the scene. A value
at most :data:`BOUNDS_TOLERANCE` beyond a joint's URDF range is moved onto it and noted, as
MoveIt's start-state bounds fixing does (which allows 0.05 rad); farther, it is left for the
scene's own check to refuse, naming the joint.
"""

from __future__ import annotations

import math

from lxml import etree

from cpr_kin.common.names import repeated
from planning.io.moveit_messages import MoveItImportError, RobotState


def joint_values(*states: RobotState) -> dict[str, float]:
    """The joint values of ``states``, a later state's over an earlier one's.

    Raises:
        MoveItImportError: a joint state with more names than positions, or fewer, or a name twice.
    """
    values: dict[str, float] = {}
    for state in states:
        joint_state = state.joint_state
        if len(joint_state.position) != len(joint_state.name):
            raise MoveItImportError(
                f"joint_state has {len(joint_state.name)} names and {len(joint_state.position)} positions"
            )
        twice = repeated(joint_state.name)
        if twice:
            raise MoveItImportError(f"joint_state.name gives {twice} more than once; each joint once")
        values.update(zip(joint_state.name, joint_state.position, strict=True))
    return values


def wrapped(
    values: dict[str, float],
    continuous: set[str],
    towards: dict[str, float] | None = None,
    notes: list[str] | None = None,
) -> dict[str, float]:
    """``values`` with those of ``continuous`` joints turned by whole turns [rad].

    Into [-pi, pi], or, where ``towards`` (values within it) gives the joint, to the nearest of
    its value: within pi of it, so a motion from it turns the short way round. Each value turned
    is said in ``notes``.
    """
    towards = towards or {}

    def turned(joint: str, value: float) -> float:
        if joint not in continuous:
            return value
        if joint not in towards:
            return math.remainder(value, math.tau)
        return towards[joint] + math.remainder(value - towards[joint], math.tau)

    result = {j: turned(j, v) for j, v in values.items()}
    said = notes if notes is not None else []
    for joint in sorted(j for j in continuous & set(values) if abs(result[j] - values[j]) > 1e-12):
        near = f"the start's {towards[joint]:.6g}" if joint in towards else "0"
        said.append(
            f"{joint} = {values[joint]!r} turned by whole turns to {result[joint]:.6g} rad, within pi of "
            f"{near} (a continuous joint: the same pose, the short way round)"
        )
    return result


BOUNDS_TOLERANCE = 1e-4
"""A joint value this far [rad or m] beyond its URDF range is moved onto it (MoveIt's start-state
bounds fixing allows 0.05 rad); farther, it is left for the scene's check to refuse."""


def position_ranges(tree: etree._ElementTree) -> dict[str, tuple[float, float]]:
    """The URDF's position limits of its revolute and prismatic joints."""
    ranges = {}
    for joint in tree.getroot().findall("joint"):
        limit = joint.find("limit")
        if joint.get("type") in ("revolute", "prismatic") and limit is not None:
            ranges[joint.get("name", "")] = (float(limit.get("lower", 0.0)), float(limit.get("upper", 0.0)))
    return ranges


def within_ranges(
    values: dict[str, float], ranges: dict[str, tuple[float, float]], notes: list[str]
) -> dict[str, float]:
    """``values``, those within :data:`BOUNDS_TOLERANCE` beyond their range moved onto it (and noted)."""
    moved = {}
    for name, value in values.items():
        low, high = ranges.get(name, (-math.inf, math.inf))
        if low - BOUNDS_TOLERANCE <= value < low or high < value <= high + BOUNDS_TOLERANCE:
            moved[name] = min(max(value, low), high)
            notes.append(f"{name} = {value!r} moved onto its range [{low:g}, {high:g}]")
    return values | moved
