"""A robot's collision geometries, named as in its URDF and sorted into the two collision groups.

The ``effector`` group holds the geometries of the links the tool frame's joint carries (or,
when those have no collision geometry, the nearest joint above that does; or the links a
robot spec names), the ``links`` group every other one (:data:`cpr_kin.model.robot.GROUPS`). The
paper's fitness tells the two apart; a robot needs geometry in both.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import pinocchio as pin

from cpr_kin.common.errors import UrdfError
from cpr_kin.model.frames import frame_index
from cpr_kin.model.robot import GROUPS, RobotGeometry


def carried_alone(model: Any, collision: Any, tcp: str) -> set[str]:
    """The links (body frames) of the last joint up from ``tcp`` that carries collision geometry.

    The joint that carries the tool frame, or, when its links have no collision geometry (a
    gripper described only visually, as the SO-100's), the nearest joint above it that does.
    """
    joint = model.frames[frame_index(model, tcp)].parentJoint
    carriers = {obj.parentJoint for obj in collision.geometryObjects}
    while joint > 0 and joint not in carriers:
        joint = model.parents[joint]
    return {f.name for f in model.frames if f.type == pin.FrameType.BODY and f.parentJoint == joint}


def grouped_geometries(
    model: Any,
    collision: Any,
    names_by_link: Mapping[str, Sequence[str]],
    effector: set[str],
    path: Path,
) -> tuple[RobotGeometry, ...]:
    """The collision geometries of the URDF at ``path``, named as in it and sorted into their groups.

    Raises:
        UrdfError: the URDF has no collision geometry, or none in a group (the fix named).
    """
    geometries = []
    used: dict[str, int] = {}
    for index, obj in enumerate(collision.geometryObjects):
        link = model.frames[obj.parentFrame].name
        k = used.get(link, 0)
        used[link] = k + 1
        names = names_by_link.get(link, ())
        name = names[k] if k < len(names) else f"{link}_{k}"
        obj.name = name
        group = "effector" if link in effector else "links"
        geometries.append(RobotGeometry(name=name, link=link, group=group, index=index))
    if not geometries:
        raise UrdfError(
            f"URDF '{path}' has no <collision> geometry: the planner keeps its clearances between "
            "collision shapes; give the links <collision> elements"
        )
    for group in GROUPS:
        if not any(g.group == group for g in geometries):
            fix = (
                f"name links that have shapes in effector_links (now {sorted(effector)})"
                if group == "effector"
                else "give the links before the tool <collision> shapes, or name fewer effector_links"
            )
            raise UrdfError(
                f"URDF '{path}' has no collision geometry in group '{group}' (the effector: the links "
                f"the tool frame's joint carries, the links: the others); {fix}"
            )
    return tuple(geometries)
