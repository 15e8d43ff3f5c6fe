"""The arm of a URDF's kinematic tree: the joints a robot plans with, and its tool, by default.

A URDF of an arm often carries more than the arm: a hand whose fingers are joints of their
own (the Panda's), a gripper's jaw. :func:`arm_chain` walks the tree from its root while it
does not branch into two moving subtrees; the joints met are the arm's, and where the walk
ends (or the one fixed leaf below it, such as a ``tcp`` link) is its tool.
"""

from __future__ import annotations

from dataclasses import dataclass

from lxml import etree


@dataclass(frozen=True)
class ArmChain:
    """The arm of a URDF's tree: its moving joints from the root, and its tool link.

    Attributes:
        joints: the moving joints met from the root while the tree does not branch into two
            moving subtrees (a hand's fingers branch), in order.
        tool: the link where the walk ends, or its only fixed descendant leaf (a tool frame
            such as ``panda_hand_tcp``) when it has exactly one.
    """

    joints: tuple[str, ...]
    tool: str


def arm_chain(tree: etree._ElementTree) -> ArmChain:
    """The arm of the URDF ``tree`` (:class:`ArmChain`): the default planned joints and tool frame."""
    children: dict[str, list[etree._Element]] = {}
    parents = set()
    for joint in tree.getroot().findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            children.setdefault(parent.get("link", ""), []).append(joint)
            parents.add(child.get("link", ""))
    roots = [
        link.get("name", "") for link in tree.getroot().findall("link") if link.get("name") not in parents
    ]

    def moves(joint: etree._Element) -> bool:
        child = joint.find("child")
        below = children.get("" if child is None else child.get("link", ""), [])
        return joint.get("type") != "fixed" or any(moves(j) for j in below)

    link, joints = (roots[0] if roots else ""), []
    while True:
        moving = [j for j in children.get(link, []) if moves(j)]
        if len(moving) != 1:
            break
        joint = moving[0]
        if joint.get("type") != "fixed":
            joints.append(joint.get("name", ""))
        child = joint.find("child")
        link = "" if child is None else child.get("link", "")
    leaves: list[str] = []
    frontier = [link]
    while frontier:
        below = [j for j in children.get(frontier.pop(), []) if j.get("type") == "fixed"]
        for joint in below:
            child = joint.find("child")
            name = "" if child is None else child.get("link", "")
            (frontier if children.get(name) else leaves).append(name)
    return ArmChain(tuple(joints), leaves[0] if len(leaves) == 1 else link)
