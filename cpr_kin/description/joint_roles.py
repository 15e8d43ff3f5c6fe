"""Which joints of a URDF are planned, which held, and at what values.

The planned joints are those a :class:`~cpr_kin.description.loading.RobotSpec` names, or by
default the arm's (:func:`~cpr_kin.model.arm.default_joints`). Every other joint is held: at
the value given, a ``mimic`` joint at ``multiplier x leader + offset`` of its (held) leader, a
``planar`` or ``floating`` joint (a mobile base's, :func:`base_joints`) at its identity pose,
any other at 0 clipped into its range.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from lxml import etree

from cpr_kin.common.errors import UrdfError
from cpr_kin.description.supported import BASE_TYPES
from cpr_kin.model.arm import ArmChain, default_joints


def base_joints(tree: etree._ElementTree) -> tuple[str, ...]:
    """The URDF's ``planar`` and ``floating`` joints (a mobile base's), in file order."""
    return tuple(j.get("name", "") for j in tree.getroot().findall("joint") if j.get("type") in BASE_TYPES)


def _refuse_fixed(tree: etree._ElementTree, given: list[str], key: str, names: Any, path: Path) -> None:
    """Refuse names in ``given`` (of option ``key``) of the URDF's fixed joints, which never move."""
    fixed = sorted(set(given) & {j.get("name") for j in tree.getroot().findall("joint")})
    if fixed:
        raise UrdfError(
            f"URDF '{path}': {key} names fixed joint(s) {fixed}; its movable joints: {list(names)}"
        )


def _range(model: Any, joint: str) -> tuple[float, float]:  # a joint's position range [rad or m]
    i = model.joints[model.getJointId(joint)].idx_q
    return float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])


def planned_joints(
    joints: tuple[str, ...] | None,
    tcp: str | None,
    model: Any,
    tree: etree._ElementTree,
    path: Path,
    arm: ArmChain,
    bases: tuple[str, ...],
) -> tuple[str, ...]:
    """The planned joints: ``joints`` checked against the URDF's, or its default ones.

    Args:
        joints: the joints a :class:`~cpr_kin.description.loading.RobotSpec` names, or ``None``.
        tcp: the tool frame it names, or ``None``.
        model: the URDF's Pinocchio model (every joint).
        tree: the URDF's XML.
        path: the URDF file, for messages.
        arm: its :func:`~cpr_kin.model.arm.arm_chain`.
        bases: its :func:`base_joints`, never planned.

    Raises:
        UrdfError: a joint the URDF lacks, a fixed, mimic or base joint, the joints out of
            the URDF's chain order, or none named and none to plan (no moving joint, or
            none between the root and ``tcp``).
    """
    names = tuple(model.names[1:])
    mimics = {j.get("name") for j in tree.getroot().findall("joint") if j.find("mimic") is not None}
    if joints is None:
        planned = default_joints(model, arm, tcp, mimics | set(bases), path)
        if not planned:
            where = "" if tcp is None else f" between its root and the tool frame '{tcp}'"
            raise UrdfError(
                f"URDF '{path}' has no joint to plan{where}: a planned joint is revolute, "
                "prismatic or continuous, mimics none and is no base's planar or floating joint "
                f"(its moving joints: {list(names)}); "
                + ("give the robot a joint" if tcp is None else "name a tool frame the joints move")
            )
        return planned
    named_bases = [j for j in joints if j in bases]
    if named_bases:
        raise UrdfError(
            f"URDF '{path}': joints names {named_bases}, a base's planar or floating joint(s): they are "
            "held at their identity pose, never planned; plan the arm's joints, with the obstacles "
            "given in the base's frame"
        )
    unknown = [j for j in joints if j not in names]
    _refuse_fixed(tree, unknown, "joints", names, path)
    if unknown:
        raise UrdfError(f"URDF '{path}' has no joint(s) {unknown}; its joints are {list(names)}")
    order = [j for j in names if j in joints]
    if tuple(order) != tuple(joints) or len(set(joints)) != len(joints):
        raise UrdfError(
            f"URDF '{path}': joints = {list(joints)}; give each once, in the URDF's chain order {order}"
        )
    planned_mimics = sorted(mimics & set(joints))
    if planned_mimics:
        raise UrdfError(f"URDF '{path}': joint(s) {planned_mimics} mimic another; they cannot be planned")
    return tuple(joints)


def held_values(
    given: dict[str, float], model: Any, tree: etree._ElementTree, unheld: tuple[str, ...], path: Path
) -> dict[str, float]:
    """The value of each held joint [rad or m] (the loader's step 4), checked against its range.

    Args:
        given: the values a :class:`~cpr_kin.description.loading.RobotSpec` holds joints at.
        model: the URDF's Pinocchio model (every joint).
        tree: the URDF's XML.
        unheld: the planned joints and the base's planar or floating ones (held at their
            identity pose, never at a given value).
        path: the URDF file, for messages.

    Raises:
        UrdfError: a held name the URDF lacks, or of a fixed, planned or base joint; a value
            outside its joint's range; a mimic joint held off its leader's value.
    """
    names = tuple(model.names[1:])
    unknown = sorted(set(given) - set(names))
    _refuse_fixed(tree, unknown, "held", names, path)
    if unknown or set(given) & set(unheld):
        problem = (
            f"no joint(s) {unknown}"
            if unknown
            else f"planned or base joint(s) {sorted(set(given) & set(unheld))}"
        )
        held_ones = [n for n in names if n not in unheld]
        raise UrdfError(f"URDF '{path}': held names {problem}; hold joints of {held_ones}")
    mimic = {
        j.get("name"): j.find("mimic") for j in tree.getroot().findall("joint") if j.find("mimic") is not None
    }
    values: dict[str, float] = {}
    for name in (n for n in names if n not in unheld):
        i = model.joints[model.getJointId(name)].idx_q
        low, high = float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])
        value = float(given.get(name, np.clip(0.0, low, high)))
        leader = mimic[name].get("joint", "") if name in mimic else ""
        if name in mimic and (name not in given or leader in names):
            if leader not in names:
                raise UrdfError(
                    f"URDF '{path}': joint '{name}' mimics joint '{leader}', which the URDF does not "
                    f"have; name one of its joints in the <mimic>, or hold '{name}' (held={{...}})"
                )
            if leader in unheld:
                raise UrdfError(
                    f"URDF '{path}': joint '{name}' mimics planned joint '{leader}'; a joint that follows "
                    f"a planned one is not supported: hold '{leader}' too (held: {{{leader}: value}}) "
                    "or name the planned joints without it (joints: [...])"
                )
            multiplier = float(mimic[name].get("multiplier", "1"))
            offset = float(mimic[name].get("offset", "0"))
            lead = given.get(leader, float(np.clip(0.0, *_range(model, leader))))
            follows = multiplier * lead + offset
            if name in given and abs(value - follows) > 1e-9:
                raise UrdfError(
                    f"URDF '{path}': held joint '{name}' = {value:g} mimics '{leader}' = {lead:g} "
                    f"({multiplier:g} x '{leader}' + {offset:g} = {follows:g}); hold '{leader}' "
                    f"and leave '{name}' to follow it"
                )
            value = follows
        if not low - 1e-9 <= value <= high + 1e-9:
            raise UrdfError(f"URDF '{path}': held joint '{name}' = {value:g} is outside [{low:g}, {high:g}]")
        values[name] = value
    return values
