"""An SRDF's planning groups: the joints a MoveIt group plans, and its tip link.

A ``<group>`` holds ``<chain base_link tip_link>`` (the joints on the URDF's path from base to
tip), ``<joint name>``, ``<link name>`` (the joint above that link) and ``<group name>``
(another group's joints). :func:`group_joints` gives the moving ones, in the URDF's order.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cpr_kin.collision.srdf_pairs import parse_srdf
from cpr_kin.common.errors import UrdfError


@dataclass(frozen=True)
class PlanningGroup:
    """A MoveIt planning group of an SRDF.

    Attributes:
        name: the group's name.
        joints: its moving joints, in the URDF's order.
        tip: the tip link of its (last) chain, or ``None`` if it has no chain.
    """

    name: str
    joints: tuple[str, ...]
    tip: str | None


def group_joints(srdf: Path, group: str, urdf: etree._ElementTree) -> PlanningGroup:
    """The planning group ``group`` of the SRDF file ``srdf``, on the robot of the URDF tree ``urdf``.

    Raises:
        UrdfError: the SRDF is unreadable, has no such group (the message lists its groups), or
            names a joint or link the URDF lacks.
    """
    root = parse_srdf(srdf)
    groups = {g.get("name", ""): g for g in root.findall("group")}
    joints = {j.get("name", ""): j for j in urdf.getroot().findall("joint")}
    above = {
        j.find("child").get("link", ""): name for name, j in joints.items() if j.find("child") is not None
    }
    order = list(joints)

    def chain(base: str, tip: str) -> list[str]:
        path, link = [], tip
        while link != base:
            if link not in above:
                raise UrdfError(
                    f"SRDF group '{group}': no chain from link '{base}' to link '{tip}' in the URDF"
                )
            path.append(above[link])
            parent = joints[above[link]].find("parent")
            link = "" if parent is None else parent.get("link", "")
        return path[::-1]

    def collect(name: str, seen: tuple[str, ...]) -> tuple[list[str], str | None]:
        if name not in groups:
            raise UrdfError(f"SRDF file '{srdf}' has no group '{name}'; its groups: {sorted(groups)}")
        if name in seen:
            raise UrdfError(f"SRDF group '{name}' contains itself")
        found: list[str] = []
        tip = None
        for element in groups[name]:
            if element.tag == "chain":
                found += chain(element.get("base_link", ""), element.get("tip_link", ""))
                tip = element.get("tip_link")
            elif element.tag == "joint":
                found.append(element.get("name", ""))
            elif element.tag == "link" and element.get("name", "") in above:
                found.append(above[element.get("name", "")])
            elif element.tag == "group":
                more, sub_tip = collect(element.get("name", ""), (*seen, name))
                found += more
                tip = tip or sub_tip
        unknown = sorted({j for j in found if j not in joints})
        if unknown:
            raise UrdfError(f"SRDF group '{name}' names joint(s) {unknown} the URDF lacks")
        return found, tip

    found, tip = collect(group, ())
    moving = sorted({j for j in found if joints[j].get("type") != "fixed"}, key=order.index)
    return PlanningGroup(name=group, joints=tuple(moving), tip=tip)
