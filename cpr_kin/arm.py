"""The arm of a URDF's kinematic tree: the joints a robot plans with, and its tool, by default.

A URDF of an arm often carries more than the arm: a hand whose fingers are joints of their
own (the Panda's), a gripper's jaw. :func:`arm_chain` walks the tree from its root while it
does not branch into two moving subtrees; the joints met are the arm's, and where the walk
ends (or the one fixed leaf below it, such as a ``tcp`` link) is its tool. A last moving joint
beside a tool frame (a fixed leaf link with no geometry, as the SO-101's ``gripper_frame_link``
beside its jaw) is a gripper's: the walk ends before it, at the tool frame.
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
    """The arm of the URDF ``tree`` (:class:`ArmChain`): the default planned joints and tool frame.

    Of several fixed leaves below the arm's end, the one without geometry (a tool frame such
    as the UR's ``tool0`` beside its ``ee_link`` box) is the tool; if none or several, the end link.
    """
    children: dict[str, list[etree._Element]] = {}
    parents = set()
    for joint in tree.getroot().findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            children.setdefault(parent.get("link", ""), []).append(joint)
            parents.add(child.get("link", ""))
    links = {link.get("name", ""): link for link in tree.getroot().findall("link")}
    roots = [name for name in links if name not in parents]

    def child_of(joint: etree._Element) -> str:
        child = joint.find("child")
        return "" if child is None else child.get("link", "")

    def moves(joint: etree._Element) -> bool:
        return joint.get("type") != "fixed" or any(moves(j) for j in children.get(child_of(joint), []))

    def bare(link: str) -> bool:
        element = links.get(link)
        return element is not None and element.find("visual") is None and element.find("collision") is None

    def fixed_leaves(link: str) -> list[str]:
        """The leaf links that fixed joints attach below ``link``."""
        leaves: list[str] = []
        frontier = [link]
        while frontier:
            for joint in children.get(frontier.pop(), []):
                if joint.get("type") == "fixed":
                    name = child_of(joint)
                    (frontier if children.get(name) else leaves).append(name)
        return leaves

    link = roots[0] if roots else ""
    joints: list[str] = []
    while True:
        moving = [j for j in children.get(link, []) if moves(j)]
        if len(moving) != 1:
            break
        joint = moving[0]
        if joint.get("type") != "fixed":
            frames = [leaf for leaf in fixed_leaves(link) if bare(leaf)]
            jaw = not any(moves(j) for j in children.get(child_of(joint), []))
            if jaw and len(frames) == 1:
                return ArmChain(tuple(joints), frames[0])  # a gripper's last joint beside the tool frame
            joints.append(joint.get("name", ""))
        link = child_of(joint)
    leaves = fixed_leaves(link)
    frames = [leaf for leaf in leaves if bare(leaf)]
    tool = leaves[0] if len(leaves) == 1 else frames[0] if len(frames) == 1 else link
    return ArmChain(tuple(joints), tool)
