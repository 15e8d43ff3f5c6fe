"""A URDF's links form one tree hanging from one root link: what a serial arm's model needs.

Each joint's ``<parent link>`` and ``<child link>`` name links of the file; a link is the child
of one joint at most; exactly one link is no joint's child (the root); and no joints close a
loop. A closed chain (a parallel gripper's linkage written as a loop) or a stray second root
made Pinocchio's parser build the root link alone, and the loader then said the tool frame was
missing; :func:`check_tree` names the joints of the loop, the two parents or the roots instead.
"""

from __future__ import annotations

from pathlib import Path

from lxml import etree

from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import escaped, listed, repeated

MAX_NAMED = 8
"""Most names a message lists (a robot's links run to hundreds)."""


def check_tree(tree: etree._ElementTree, path: Path) -> None:
    """Refuse joints and links that do not form one tree hanging from one root link.

    Each joint's ``<parent link>`` and ``<child link>`` name links of the file; a link is the
    child of one joint at most; exactly one link is no joint's child (the root); every link
    hangs from it, which with the rules before fails only where joints close a loop (walking
    up from a link never reaches the root). The message names the joints and links at fault.
    """
    root = tree.getroot()
    links = [link.get("name", "") for link in root.findall("link")]
    joints = root.findall("joint")
    for kind, names in (("link", links), ("joint", [joint.get("name", "") for joint in joints])):
        twice = repeated(names)
        if twice:
            raise UrdfError(
                f"URDF '{path}': {kind} name(s) {listed(twice, MAX_NAMED)} are defined more than once; "
                "names are unique"
            )
    defined = set(links)
    parent_of: dict[str, tuple[str, str]] = {}  # child link -> (joint, parent link)
    for joint in joints:
        name = joint.get("name", "?")
        ends = {}
        for end in ("parent", "child"):
            element = joint.find(end)
            link = None if element is None else element.get("link")
            if link is None or link not in defined:
                what = f"has no <{end} link=...>" if link is None else f"names {end} link '{escaped(link)}'"
                raise UrdfError(
                    f"URDF '{path}': joint '{escaped(name)}' {what}, which the file does not define; "
                    f"a joint joins two of its links ({listed(links, MAX_NAMED)})"
                )
            ends[end] = link
        child = ends["child"]
        if child in parent_of:
            first = parent_of[child][0]
            raise UrdfError(
                f"URDF '{path}': link '{escaped(child)}' is the child of joints '{escaped(first)}' and "
                f"'{escaped(name)}'; a link hangs from one joint at most (a URDF is a tree: closed chains "
                "are not supported)"
            )
        parent_of[child] = (name, ends["parent"])
    roots = [link for link in links if link not in parent_of]
    if len(roots) > 1:
        raise UrdfError(
            f"URDF '{path}': links {listed(roots, MAX_NAMED)} are each the child of no joint; "
            f"a URDF's links hang from one root: join the others to '{escaped(roots[0])}'s tree by a "
            "joint ('fixed' where they do not move) or remove them"
        )
    reached = set(roots)
    for link in links:
        walked: list[str] = []
        while link not in reached and link not in walked:
            walked.append(link)
            link = parent_of[link][1]
        if link not in reached:  # the walk came back to ``link``: a loop, walked upwards
            loop = [parent_of[child] + (child,) for child in walked[walked.index(link) :]][::-1]
            closing = ", ".join(
                f"'{escaped(j)}' ({escaped(p)} -> {escaped(c)})" for j, p, c in loop[:MAX_NAMED]
            )
            raise UrdfError(
                f"URDF '{path}': joints {closing} close a loop, which hangs from no root link; a URDF's "
                "links form a tree: closed chains are not supported"
            )
        reached.update(walked)
