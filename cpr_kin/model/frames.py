"""A frame of a Pinocchio model by its name, also where a URDF gives a joint and a link one name.

Pinocchio makes a frame of every link (``BODY``) and of every joint (``JOINT``, or
``FIXED_JOINT`` for a fixed one); a URDF may name a joint as its child link (the B1-Z1's
``gripperStator``), and Pinocchio's ``getFrameId(name)`` then refuses to choose. A name here
means the link's frame first, then an operational frame, then the joint's.
"""

from __future__ import annotations

from typing import Any

import pinocchio as pin

PREFERENCE = (
    pin.FrameType.BODY,
    pin.FrameType.OP_FRAME,
    pin.FrameType.FIXED_JOINT,
    pin.FrameType.JOINT,
    pin.FrameType.SENSOR,
)
"""The order in which frames of one name are preferred."""


def frame_index(model: Any, name: str) -> int:
    """The id of ``model``'s frame ``name`` (module docstring); ``-1`` when it has none."""
    for kind in PREFERENCE:  # Pinocchio's own lookup, asked by type
        if model.existFrame(name, kind):
            return int(model.getFrameId(name, kind))
    return -1


def link_names(model: Any) -> set[str]:
    """The names of ``model``'s links (its ``BODY`` frames)."""
    return {f.name for f in model.frames if f.type == pin.FrameType.BODY}
