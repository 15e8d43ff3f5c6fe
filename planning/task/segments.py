"""What a task is made of: free motions, tool lines, waits, and what the robot picks up and lets go.

A task (:func:`~planning.task.task_plan.plan_task`) is a sequence of these segments; a scene
file's ``task:`` holds the same ones (:mod:`planning.io.task_entry`), each under its key
(:func:`segment_name`).
"""

from __future__ import annotations

from dataclasses import dataclass

import cpr_kin as ck
from planning.pipeline.target import Target
from planning.task.limits import LONGEST_WAIT_S
from planning.task.orientation import OrientationConstraint
from planning.task.tool_line import ToolLine
from planning.validation import number_in


@dataclass(frozen=True)
class Move:
    """A free motion to ``goal``, around the scene's obstacles (the planner's search).

    Attributes:
        goal: a joint, ``tcp`` or pose goal, as a scene's.
        constraint: an orientation the tool keeps all the way (an upright carry), if any;
            start and goal must keep it (:mod:`planning.task.held_orientation`).
    """

    goal: Target
    constraint: OrientationConstraint | None = None


@dataclass(frozen=True)
class Wait:
    """Standing still for ``seconds`` [s] (a grasp closing, a part settling)."""

    seconds: float

    def __post_init__(self) -> None:
        number_in("wait seconds", self.seconds, 0.0, LONGEST_WAIT_S, "s", low_open=True)


@dataclass(frozen=True)
class Attach:
    """From here on the robot carries ``payload``: its mass in the torques, its shape in the checks.

    Attributes:
        payload: the object grasped (its frame, shape and the links it may touch, its
            ``touch_links``, as a scene's payload).
    """

    payload: ck.Payload


@dataclass(frozen=True)
class Detach:
    """From here on the robot carries nothing (the object released).

    Attributes:
        name: the object released, checked against what the robot carries; ``None``: whatever
            it carries.
    """

    name: str | None = None


Segment = Move | ToolLine | Wait | Attach | Detach
KINDS = {Move: "free", ToolLine: "line", Wait: "wait", Attach: "attach", Detach: "detach"}
"""Each segment's kind, as a task's record names it."""


def segment_name(segment: object) -> str:
    """The segment's key in a scene file's ``task:`` (``move``, ``line``, ...): its class, lower case."""
    return "line" if isinstance(segment, ToolLine) else type(segment).__name__.lower()
