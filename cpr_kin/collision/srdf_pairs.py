"""Which pairs of a robot's own links are checked: the SRDF's disabled pairs, and the rule of adjacency.

The pairs checked are those of collision geometries on links that are not adjacent (two
links carried by the same joint, or by a joint and its parent joint, touch by design),
minus the link pairs an SRDF's ``<disable_collisions>`` lists (MoveIt's: adjacent, always
in contact, or never able to meet). Loading a robot reads them here; their distances are
:mod:`cpr_kin.collision.self_collision`'s, imported only for a robot that has such pairs.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from cpr_kin.common.errors import CprKinError, UrdfError
from cpr_kin.common.names import cut
from cpr_kin.common.user_files import read_bytes

LinkPair = frozenset[str]

MAX_SRDF_BYTES = 10_000_000
"""Largest SRDF file [bytes]."""


def find_srdf(urdf_path: Path, robot_name: str | None = None) -> Path | None:
    """The SRDF of a URDF by the default rule (:attr:`cpr_kin.RobotSpec.srdf`), or ``None``.

    Looked for, in order: ``<urdf stem>.srdf`` beside the URDF, then in a ``srdf`` folder
    beside the URDF's folder; then the same with the URDF's robot name (``<robot name=...>``,
    MoveIt's rule: ``ur5_robot.urdf`` names robot ``ur5``, whose SRDF is ``srdf/ur5.srdf``).
    """
    stems = [urdf_path.stem] + ([robot_name] if robot_name and robot_name != urdf_path.stem else [])
    for stem in stems:
        for candidate in (
            urdf_path.parent / f"{stem}.srdf",
            urdf_path.parent.parent / "srdf" / f"{stem}.srdf",
        ):
            if candidate.is_file():
                return candidate
    return None


@dataclass(frozen=True)
class SrdfPairs:
    """The ``<disable_collisions>`` of an SRDF.

    Attributes:
        disabled: the link pairs it disables, both links known to the URDF.
        unknown_links: links it names that the URDF lacks; their entries are skipped, as
            MoveIt skips them (with a warning), and the loaded robot reports them.
    """

    disabled: frozenset[LinkPair]
    unknown_links: tuple[str, ...] = ()


def parse_srdf(path: Path) -> etree._Element:
    """The root element of the SRDF file ``path``, parsed as strict XML (no entities, no network).

    Raises:
        UrdfError: the file is missing, too large or not well-formed XML.
    """
    parser = etree.XMLParser(recover=False, resolve_entities=False, no_network=True)
    try:
        root = etree.fromstring(read_bytes(path, MAX_SRDF_BYTES, "SRDF file"), parser)
    except etree.XMLSyntaxError as exc:
        raise UrdfError(f"SRDF file '{path}' is not well-formed XML: {str(exc)[:120]}") from None
    except CprKinError as exc:
        raise UrdfError(str(exc)) from None
    if root.tag != "robot":
        raise UrdfError(
            f"SRDF file '{path}' has root element <{cut(str(root.tag), 40)}>; an SRDF's is <robot>"
        )
    if root.find("link") is not None or root.find("joint") is not None:
        raise UrdfError(
            f"SRDF file '{path}' holds <link> or <joint> elements: it is a URDF; give the robot's "
            "SRDF (groups, disable_collisions), which MoveIt's setup assistant writes"
        )
    return root


def read_srdf(path: Path, links: Iterable[str]) -> SrdfPairs:
    """The link pairs an SRDF disables (:class:`SrdfPairs`), as MoveIt reads them.

    Those ``<disable_collisions link1 link2>`` lists, and every pair of a link that
    ``<disable_default_collisions link>`` names, but those ``<enable_collisions link1 link2>``
    lists (srdfdom's default entries and their exceptions).

    Raises:
        UrdfError: the file is unreadable or not XML.
    """
    root = parse_srdf(path)
    known = set(links)
    unknown: set[str] = set()

    def listed(tag: str) -> set[LinkPair]:
        found = set()
        for element in root.iter(tag):
            pair = (element.get("link1", ""), element.get("link2", ""))
            missing = {link for link in pair if link not in known}
            unknown.update(missing)
            if not missing:
                found.add(frozenset(pair))
        return found

    pairs, enabled = listed("disable_collisions"), listed("enable_collisions")
    for element in root.iter("disable_default_collisions"):
        link = element.get("link", "")
        if link not in known:
            unknown.add(link)
            continue
        pairs |= {frozenset((link, other)) for other in known if other != link} - enabled
    return SrdfPairs(frozenset(pairs), tuple(sorted(unknown)))


def adjacent(model: Any, joint_a: int, joint_b: int) -> bool:
    """Links on joints ``joint_a`` and ``joint_b`` are adjacent: the same joint, or one the other's parent."""
    return bool(joint_a == joint_b or model.parents[joint_a] == joint_b or model.parents[joint_b] == joint_a)


def self_pairs(
    model: Any, collision_model: Any, disabled: frozenset[LinkPair]
) -> tuple[tuple[int, int], ...]:
    """Geometry index pairs ``(a, b)``, ``a < b``, on non-adjacent links not ``disabled``.

    Links are the frames the geometries hang on; two links are adjacent when the same joint
    carries both, or the joint of one is the parent of the other's.
    """
    objects = collision_model.geometryObjects
    found = []
    for a in range(len(objects)):
        for b in range(a + 1, len(objects)):
            if adjacent(model, objects[a].parentJoint, objects[b].parentJoint):
                continue
            link_a = model.frames[objects[a].parentFrame].name
            link_b = model.frames[objects[b].parentFrame].name
            if frozenset((link_a, link_b)) in disabled or link_a == link_b:
                continue
            found.append((a, b))
    return tuple(found)
