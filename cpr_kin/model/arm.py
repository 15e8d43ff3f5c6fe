"""The arm of a URDF's kinematic tree: the joints a robot plans with, and its tool, by default.

A URDF of an arm often carries more than the arm: a hand whose fingers are joints of their
own (the Panda's), a gripper's jaw. :func:`arm_chain` walks the tree from its root while it
does not branch into two moving subtrees; the joints met are the arm's, and where the walk
ends (or the one fixed leaf below it, such as a ``tcp`` link) is its tool. A last moving joint
beside a tool frame (a fixed leaf link with no geometry, as the SO-101's ``gripper_frame_link``
beside its jaw) is a gripper's: the walk ends before it, at the tool frame.

A tree that branches before its second joint (a mobile manipulator's base into its arms and
head, a humanoid's torso) has no such arm: :func:`default_joints` then asks for the tool
frame, and plans the joints from the root to it.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lxml import etree

from cpr_kin.common.errors import UrdfError
from cpr_kin.model.frames import frame_index


@dataclass(frozen=True)
class ArmChain:
    """The arm of a URDF's tree: its moving joints from the root, and its tool link.

    Attributes:
        joints: the moving joints met from the root while the tree does not branch into two
            moving subtrees (a hand's fingers branch), in order.
        tool: the link where the walk ends, or its only fixed descendant leaf (a tool frame
            such as ``panda_hand_tcp``) when it has exactly one.
        branches: where the walk ended at a branch, the first link of each moving subtree.
    """

    joints: tuple[str, ...]
    tool: str
    branches: tuple[str, ...] = ()


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
    return ArmChain(tuple(joints), tool, tuple(child_of(j) for j in moving))


def default_joints(
    model: Any, arm: ArmChain, tcp: str | None, unplanned: set[str], path: Path
) -> tuple[str, ...]:
    """The planned joints when none are named: the arm's, or those from the root to ``tcp``.

    Args:
        model: the URDF's Pinocchio model (every joint).
        arm: its :func:`arm_chain`.
        tcp: the tool frame the user named (a link or joint name), or ``None``.
        unplanned: the joints never planned: those that mimic another, a base's planar or
            floating ones.
        path: the URDF file, for messages.

    Raises:
        UrdfError: no ``tcp`` is named and the tree branches before its second joint
            (module docstring), naming the branches. (A ``tcp`` the model does not have is
            the loader's to name.)
    """
    names = tuple(model.names[1:])
    if tcp is not None and model.existFrame(tcp):
        supports = model.supports[model.frames[frame_index(model, tcp)].parentJoint]
        along = {model.names[j] for j in supports}
        return tuple(n for n in names if n in along and n not in unplanned)
    planned = tuple(n for n in names if n in arm.joints and n not in unplanned)
    others = [n for n in names if n not in arm.joints and n not in unplanned]
    if len(planned) < 2 and others:
        raise UrdfError(
            f"URDF '{path}' has no single arm: its tree branches after {len(planned)} joint(s) "
            f"{list(planned)} at link '{arm.tool}' into {list(arm.branches)}, {len(others)} more "
            "moving joints; name the tool frame (robot: {urdf: ..., tcp: <link>}: the joints from "
            "the root to it are planned) or the joints (joints: [...])"
        )
    return planned
