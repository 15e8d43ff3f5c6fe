"""What the planner supports of a URDF: joint types, bounded ranges and limits, printable names.

A URDF can describe what no plan should be asked of: a joint that turns without end, a
range of a thousand turns, a velocity limit of a micrometre per second. Left in, such a
joint makes the search's box, the trajectories and their checks as large as the range or
as long as the crossing time, and a plan runs for minutes and gigabytes. So the loader
refuses it at once (:class:`~cpr_kin.common.errors.UrdfError`, exit 2 on the command line), naming
the joint, the value and what is supported:

- joint types: ``revolute``, ``prismatic``, ``continuous`` (planned within
  :data:`~cpr_kin.description.urdf_file.CONTINUOUS_RANGE_RAD`) and ``fixed``; ``floating`` and
  ``planar`` joints are not planned, and a ``mimic`` joint is held (with the joint it
  mimics); each moving joint with an axis that is a direction;
- position limits within :data:`MAX_REVOLUTE_RAD` (one turn either way) for a revolute
  joint and :data:`MAX_PRISMATIC_M` for a prismatic one, with ``lower < upper``;
- crossing a joint's whole range, at rest at both ends, within its velocity, acceleration
  and jerk limits takes at most :data:`MAX_CROSSING_S` (a plan's motion is a few such
  crossings at most);
- link, joint and collision names without control or bidirectional characters
  (:mod:`cpr_kin.common.names`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from lxml import etree

from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import escaped, unprintable
from cpr_kin.description.urdf_file import parse_urdf, validate_urdf
from cpr_kin.model.limits import JointLimits

SUPPORTED_TYPES = ("revolute", "prismatic", "continuous", "fixed")
"""Joint types the planner plans (``fixed`` joints join links rigidly)."""
MAX_REVOLUTE_RAD = 2 * math.pi
"""Largest |position limit| of a revolute joint [rad]: one turn either way, as UR and xArm arms have."""
MAX_PRISMATIC_M = 10.0
"""Largest |position limit| of a prismatic joint [m]."""
LIMIT_TOLERANCE = 1e-3
"""How far a position limit may pass its bound (a URDF that writes 2 pi as 6.2832) [rad or m]."""
MAX_CROSSING_S = 600.0
"""Longest time a joint may need to cross its whole range at rest at both ends [s] (the
longest fixed duration a scene may ask is the same)."""


def check_names(tree: etree._ElementTree, path: Path) -> None:
    """Refuse a link, joint, collision or frame name holding a control or bidirectional character."""
    for element in tree.getroot().iter("link", "joint", "collision", "visual", "material"):
        name = element.get("name")
        if name is None:
            continue
        problem = unprintable(name)
        if problem is not None:
            raise UrdfError(
                f"URDF '{path}': the {element.tag} name '{escaped(name)}' "
                f"holds {problem}; names must be printable text"
            )


def check_joints(tree: etree._ElementTree, path: Path) -> None:
    """Refuse joint types the planner does not plan, and axes that are not directions."""
    for joint in tree.getroot().findall("joint"):
        name, kind = joint.get("name", "?"), joint.get("type", "?")
        if kind not in SUPPORTED_TYPES:
            raise UrdfError(
                f"URDF '{path}': joint '{name}' is of type '{kind}'; supported: {list(SUPPORTED_TYPES)}"
            )
        axis = joint.find("axis")
        if kind != "fixed" and axis is not None:
            text = axis.get("xyz", "1 0 0")
            try:
                vector = [float(v) for v in text.split()]
            except ValueError:
                vector = []
            if len(vector) != 3 or not all(map(math.isfinite, vector)) or math.hypot(*vector) < 1e-9:
                raise UrdfError(
                    f"URDF '{path}': joint '{name}' axis xyz = '{escaped(text[:40])}' is not a direction; "
                    "give three finite numbers, not all zero (e.g. '0 0 1')"
                )


def crossing_time(width: float, velocity: float, acceleration: float, jerk: float) -> float:
    """A lower-bound-like estimate of the time to cross ``width`` at rest at both ends [s].

    The trapezoidal velocity profile's time under ``velocity`` and ``acceleration``, plus the
    ``acceleration / jerk`` that ramping the acceleration within the jerk limit adds.
    """
    if width >= velocity**2 / acceleration:
        trapezoid = width / velocity + velocity / acceleration
    else:
        trapezoid = 2.0 * math.sqrt(width / acceleration)
    return trapezoid + acceleration / jerk


def check_limits(limits: JointLimits, units: Sequence[str], path: Path) -> None:
    """Refuse position ranges and limits beyond what the planner supports (module docstring)."""
    for i, name in enumerate(limits.names):
        unit = units[i]
        bound = MAX_REVOLUTE_RAD if unit == "rad" else MAX_PRISMATIC_M
        lower, upper = float(limits.lower[i]), float(limits.upper[i])
        if not -bound - LIMIT_TOLERANCE <= lower < upper <= bound + LIMIT_TOLERANCE:
            raise UrdfError(
                f"URDF '{path}': joint '{name}' range [{lower:g}, {upper:g}] {unit} is not supported; "
                f"the planner supports lower < upper within [{-bound:.5g}, {bound:.5g}] {unit}"
            )
        velocity, acceleration, jerk = (
            float(v[i]) for v in (limits.velocity, limits.acceleration, limits.jerk)
        )
        crossing = crossing_time(upper - lower, velocity, acceleration, jerk)
        if crossing > MAX_CROSSING_S:
            raise UrdfError(
                f"URDF '{path}': joint '{name}' needs {crossing:.3g} s to cross its range "
                f"[{lower:g}, {upper:g}] {unit} at velocity {velocity:g} {unit}/s, acceleration "
                f"{acceleration:g} {unit}/s^2, jerk {jerk:g} {unit}/s^3; the planner supports at most "
                f"{MAX_CROSSING_S:g} s: raise the limits"
            )


def checked_urdf(path: Path, validate: bool = True) -> etree._ElementTree:
    """The URDF at ``path`` parsed and checked as the loader checks it, before anything reads it.

    Strict XML (:func:`~cpr_kin.description.urdf_file.parse_urdf`), yourdfpy's validation (unless
    ``validate`` is ``False``: a file the caller knows, such as a preset's), printable names
    and supported joints.

    Raises:
        UrdfError: naming the file and the first problem.
    """
    tree = parse_urdf(path)
    if validate:
        validate_urdf(path)
    check_names(tree, path)
    check_joints(tree, path)
    return tree
