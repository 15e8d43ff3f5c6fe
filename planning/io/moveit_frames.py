"""The frames a MoveIt file may give a pose in, as transforms to the robot's base (the URDF's root).

World-fixed frames are known: the root (also as an empty ``frame_id``), every link joined to
it by fixed joints only (a ``world`` link, a mounting plate), each ``fixed_frame_transforms``
child given in one of those, and each collision object (MoveIt names an object's frame by its
id). A link that a movable joint moves has no place until a configuration is chosen: a pose in
its frame is refused, naming the joint that moves it, as is a frame that is none of these.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from lxml import etree

from cpr_kin.common.names import cut
from planning.io.moveit_messages import MoveItImportError, TransformStamped


def _origin(joint: etree._Element) -> np.ndarray:
    """A URDF joint's ``<origin>``: its child link's frame in its parent link's.

    Raises:
        MoveItImportError: an ``xyz`` or ``rpy`` that is not three finite numbers.
    """
    origin = joint.find("origin")
    values = {}
    for key in ("xyz", "rpy"):
        text = origin.get(key, "0 0 0") if origin is not None else "0 0 0"
        try:
            values[key] = [float(v) for v in text.split()]
        except ValueError:
            values[key] = []
        if len(values[key]) != 3 or not np.all(np.isfinite(values[key])):
            raise MoveItImportError(
                f"URDF joint '{joint.get('name', '')}': <origin {key}=\"{cut(text, 40)}\"> "
                "must be three numbers"
            )
    xyz, rpy = values["xyz"], values["rpy"]
    transform = np.eye(4)
    transform[:3, :3] = pin.rpy.rpyToMatrix(*rpy)
    transform[:3, 3] = xyz
    return transform


def root_link(tree: etree._ElementTree) -> str:
    """The URDF's root link: the one no joint has as its child."""
    children = {
        j.find("child").get("link") for j in tree.getroot().findall("joint") if j.find("child") is not None
    }
    roots = [
        link.get("name", "") for link in tree.getroot().findall("link") if link.get("name") not in children
    ]
    return roots[0] if roots else ""


@dataclass
class Frames:
    """World-fixed frames by name, each as its ``(4, 4)`` pose in the robot's base [m].

    Attributes:
        root: the URDF's root link (the robot's base).
        fixed: the world-fixed frames and their poses in the base.
        moving: each link a movable joint moves, with the first such joint from the root.
    """

    root: str
    fixed: dict[str, np.ndarray] = field(default_factory=dict)
    moving: dict[str, str] = field(default_factory=dict)

    @classmethod
    def of_urdf(cls, tree: etree._ElementTree) -> Frames:
        """The root, the links fixed to it, and the links that move (module docstring)."""
        root = root_link(tree)
        children: dict[str, list[etree._Element]] = {}
        for joint in tree.getroot().findall("joint"):
            parent = joint.find("parent")
            if parent is not None and joint.find("child") is not None:
                children.setdefault(parent.get("link", ""), []).append(joint)
        frames = cls(root=root, fixed={"": np.eye(4), root: np.eye(4)})
        stack: list[tuple[str, np.ndarray, str | None]] = [(root, np.eye(4), None)]
        while stack:  # a tree: every link is reached once
            link, pose, mover = stack.pop()
            for joint in children.get(link, []):
                child = joint.find("child").get("link", "")  # found above
                moved_by = mover or (None if joint.get("type") == "fixed" else joint.get("name", ""))
                if moved_by is None:
                    frames.fixed[child] = pose @ _origin(joint)
                else:
                    frames.moving[child] = moved_by
                stack.append((child, pose @ _origin(joint), moved_by))
        return frames

    def add_transforms(self, stamped: Iterable[TransformStamped]) -> None:
        """Add ``fixed_frame_transforms``, each given in a frame already known."""
        for k, transform in enumerate(stamped):
            parent = transform.header.frame_id
            where = f"scene.fixed_frame_transforms[{k}] ('{transform.child_frame_id}')"
            self.fixed[transform.child_frame_id] = self.pose(parent, where) @ transform.transform.matrix()

    def add_virtual_joints(self, srdf: etree._Element) -> None:
        """Add the SRDF's virtual joints' parent frames (``world``), where their child is a known frame.

        The robot's base stands at the parent frame's origin (a placement elsewhere, given by the
        state's multi-DOF joint values, is refused by the import).
        """
        for joint in srdf.findall("virtual_joint"):
            parent, child = joint.get("parent_frame", ""), joint.get("child_link", "")
            if parent and child in self.fixed and parent not in self.fixed:
                self.fixed[parent] = np.linalg.inv(self.fixed[child])

    def pose(self, name: str, where: str) -> np.ndarray:
        """The pose of frame ``name`` in the base; ``where``: the field that names it, for messages.

        Raises:
            MoveItImportError: a frame that moves with the robot, or no frame known here.
        """
        name = name.removeprefix("/")  # a ROS 1 frame id, "/world": MoveIt strips the slash too
        if name in self.fixed:
            return self.fixed[name]
        if name in self.moving:
            raise MoveItImportError(
                f"{where}: frame '{name}' is a link that joint '{self.moving[name]}' moves; give it in "
                f"a frame fixed to the world (the robot's base '{self.root}')"
            )
        known = cut(", ".join(repr(n) for n in self.fixed if n), 120)
        raise MoveItImportError(
            f"{where}: frame {cut(repr(name), 60)} is not known; the frames fixed to the world here: {known}"
        )
