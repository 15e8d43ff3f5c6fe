"""What the planner supports of a URDF: joint types, bounded ranges and limits, printable names.

A URDF can describe what no plan should be asked of: a joint that turns without end, a
range of a thousand turns, a velocity limit of a micrometre per second. Left in, such a
joint makes the search's box, the trajectories and their checks as large as the range or
as long as the crossing time, and a plan runs for minutes and gigabytes. So an endless
joint, and a range beyond one turn either way, are planned within one turn either way
(:func:`~cpr_kin.description.urdf_file.narrowed_ranges`), and the loader refuses the rest at
once (:class:`~cpr_kin.common.errors.UrdfError`, exit 2 on the command line), naming the
joint, the value and what is supported:

- joint types: ``revolute``, ``prismatic``, ``continuous`` (planned within
  :data:`~cpr_kin.description.urdf_file.CONTINUOUS_RANGE_RAD`) and ``fixed``; a ``planar`` or
  ``floating`` joint (a mobile base's) is never planned but held at its identity pose, and a
  ``mimic`` joint is held (with the joint it mimics); each moving joint with an axis that is a
  direction;
- position limits ``lower < upper``: a revolute joint's range with a part within
  :data:`MAX_REVOLUTE_RAD` (one turn either way; a wider range is planned within it,
  :func:`~cpr_kin.description.urdf_file.narrowed_ranges`), a prismatic one's within
  :data:`MAX_PRISMATIC_M`;
- crossing a joint's whole range, at rest at both ends, within its velocity, acceleration
  and jerk limits takes at most :data:`MAX_CROSSING_S` (a plan's motion is a few such
  crossings at most);
- links that form one tree (:func:`~cpr_kin.description.link_tree.check_tree`);
- link, joint and collision names without control or bidirectional characters
  (:mod:`cpr_kin.common.names`);
- limits, shapes and inertials that are finite numbers: a shape's size above zero and at most
  :data:`MAX_SHAPE_M` (boxes, cylinders, spheres; a mesh's scale not zero; a visual's may be
  zero: a plate, a disc, or nothing drawn), an effort,
  velocity, mass and moment of inertia at least zero. A NaN radius or mass made Pinocchio's
  parser drop the link's elements in silence (the loader then said the link had no collision
  geometry), and a negative one computed with nonsense.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from lxml import etree

from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import escaped, unprintable
from cpr_kin.description.link_tree import check_tree
from cpr_kin.description.urdf_file import (
    RANGE_TOLERANCE_RAD,
    SHAPE_SIZES,
    TURN_EITHER_WAY_RAD,
    numbers_in,
    parse_urdf,
    validate_urdf,
)
from cpr_kin.model.limits import JointLimits

PLANNED_TYPES = ("revolute", "prismatic", "continuous", "fixed")
"""Joint types the planner plans (``fixed`` joints join links rigidly)."""
BASE_TYPES = ("planar", "floating")
"""Joint types of a mobile base, held at their identity pose: the scene's frame is their child's."""
SUPPORTED_TYPES = PLANNED_TYPES + BASE_TYPES
"""Joint types a URDF may hold."""
MAX_REVOLUTE_RAD = TURN_EITHER_WAY_RAD
"""Largest |position limit| of a revolute joint as planned [rad]: one turn either way."""
MAX_PRISMATIC_M = 10.0
"""Largest |position limit| of a prismatic joint [m]."""
LIMIT_TOLERANCE = RANGE_TOLERANCE_RAD
"""How far a position limit may pass its bound (a URDF that writes 2 pi as 6.2832) [rad or m]."""
MAX_SHAPE_M = 100.0
"""Largest size of a link's shape [m]: a box's side, a cylinder's radius or length, a sphere's
radius, and the distance of a mesh's vertex from its link's frame. An arm's links span metres;
a mesh drawn in millimetres and given no ``scale`` reaches hundreds, and far out the distance
arithmetic loses its meaning."""
INERTIA_NAMES = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
ROUNDING_KG_M2 = 1e-12
"""How far a moment of inertia may pass below zero by rounding [kg m^2] (a milligram at a millimetre)."""
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
    """Refuse joint types the planner does not plan, axes that are not directions, bad limits.

    A limit must be a finite number, an effort or velocity one of at least zero.
    """
    for joint in tree.getroot().findall("joint"):
        name, kind = joint.get("name", "?"), joint.get("type", "?")
        if kind not in SUPPORTED_TYPES:
            raise UrdfError(
                f"URDF '{path}': joint '{name}' is of type '{kind}'; supported: {list(PLANNED_TYPES)} "
                f"(planned) and {list(BASE_TYPES)} (a base's, held at its identity pose)"
            )
        axis = joint.find("axis")
        if kind not in ("fixed", "floating") and axis is not None:
            text = axis.get("xyz", "1 0 0")
            vector = numbers_in(text, 3)
            if vector is None or not all(map(math.isfinite, vector)) or math.hypot(*vector) < 1e-9:
                raise UrdfError(
                    f"URDF '{path}': joint '{name}' axis xyz = '{escaped(text[:40])}' is not a direction; "
                    "give three finite numbers, not all zero (e.g. '0 0 1')"
                )
        limit = joint.find("limit")
        for key in ("lower", "upper", "effort", "velocity"):
            text = None if limit is None else limit.get(key)
            value = None if text is None else numbers_in(text, 1)
            least = -math.inf if key in ("lower", "upper") else 0.0
            if text is not None and (value is None or not least <= value[0] < math.inf):
                wanted = "a finite number" if key in ("lower", "upper") else "a finite number >= 0"
                raise UrdfError(
                    f"URDF '{path}': joint '{name}' limit {key} = '{escaped(text[:40])}' is not supported; "
                    f"give {wanted}"
                )


def check_shapes(tree: etree._ElementTree, path: Path) -> None:
    """Refuse a shape size outside ``(0, MAX_SHAPE_M]``, and a mesh scale that is not three numbers.

    A size is a box's sides, a cylinder's radius and length, a sphere's radius; a mesh's scale
    must be three finite numbers other than zero. A visual's size may be zero: a plate or a disc
    is drawn, a shape without area left out (:func:`~cpr_kin.description.urdf_file.draws_nothing`).
    """
    for link in tree.getroot().findall("link"):
        for element in link.iter("collision", "visual"):
            where = f"URDF '{path}': link '{link.get('name', '?')}': {element.tag}"
            draws = element.tag == "visual"  # a visual may draw nothing
            least = 0.0 if draws else math.nextafter(0.0, 1.0)
            allowed = f"[0, {MAX_SHAPE_M:g}] m (a visual may be flat)" if draws else f"(0, {MAX_SHAPE_M:g}] m"
            for shape in element.iterfind("geometry/*"):
                for name, count in SHAPE_SIZES.get(str(shape.tag), ()):
                    text = shape.get(name)
                    values = numbers_in(text, count)
                    if values is None or not all(least <= v <= MAX_SHAPE_M for v in values):
                        wanted = "a number" if count == 1 else f"{count} numbers"
                        raise UrdfError(
                            f"{where} {shape.tag} {name} = '{escaped(str(text)[:40])}' is not supported; "
                            f"give {wanted} in {allowed}"
                        )
                scale = shape.get("scale") if shape.tag == "mesh" else None
                if scale is not None:
                    values = numbers_in(scale, 3)
                    if values is None or not all(math.isfinite(v) and v != 0.0 for v in values):
                        raise UrdfError(
                            f"{where} mesh scale = '{escaped(scale[:40])}' is not supported; "
                            "give three finite numbers other than zero (e.g. '0.001 0.001 0.001')"
                        )


def check_inertials(tree: etree._ElementTree, path: Path) -> None:
    """Refuse an inertial no body has: a mass or a moment (``ixx``, ``iyy``, ``izz``) below zero.

    Either also where an entry is not finite. A moment may pass zero by rounding
    (:data:`ROUNDING_KG_M2`, or 1e-9 of the largest entry; iCub's hip has -5.4e-20). The matrix is
    not held to positive semi-definiteness: real files miss it (example-robot-data's Tiago
    antenna, Romeo's body) by amounts that change its torques little.
    """
    for link in tree.getroot().findall("link"):
        inertial = link.find("inertial")
        if inertial is None:
            continue
        where = f"URDF '{path}': link '{link.get('name', '?')}' inertial"
        mass, inertia = inertial.find("mass"), inertial.find("inertia")
        texts = {"mass": None if mass is None else mass.get("value")}
        if inertia is not None:
            texts |= {name: inertia.get(name) for name in INERTIA_NAMES}
        values = {name: numbers_in(text, 1) for name, text in texts.items() if text is not None}
        for name, value in values.items():
            if value is None or not math.isfinite(value[0]):
                raise UrdfError(f"{where} {name} = '{escaped(str(texts[name])[:40])}' is not a finite number")
        largest = max((abs(v[0]) for n, v in values.items() if v is not None and n != "mass"), default=0.0)
        rounding = max(ROUNDING_KG_M2, 1e-9 * largest)
        for name, least, unit in (
            ("mass", 0.0, "kg"),
            ("ixx", -rounding, "kg m^2"),
            ("iyy", -rounding, "kg m^2"),
            ("izz", -rounding, "kg m^2"),
        ):
            value = values.get(name)
            if value is not None and value[0] < least:
                raise UrdfError(
                    f"{where} {name} = {value[0]:g} {unit} is below zero; a body's is at least zero"
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
            supported = (
                f"a part within [{-bound:.5g}, {bound:.5g}] rad, one turn either way (a wider range is "
                "planned within it)"
                if unit == "rad"
                else f"within [{-bound:.5g}, {bound:.5g}] m"
            )
            raise UrdfError(
                f"URDF '{path}': joint '{name}' range [{lower:g}, {upper:g}] {unit} is not supported; "
                f"the planner supports lower < upper with {supported}"
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
    ``validate`` is ``False``: a file the caller knows, such as a preset's), printable names,
    links in one tree, supported joints, shapes and inertials.

    Raises:
        UrdfError: naming the file and the first problem.
    """
    tree = parse_urdf(path)
    if validate:
        validate_urdf(path)
    check_names(tree, path)
    check_tree(tree, path)
    check_joints(tree, path)
    check_shapes(tree, path)
    check_inertials(tree, path)
    return tree
