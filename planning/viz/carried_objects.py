"""What a robot carries over a trajectory, and where each object is at each instant: for drawing.

A task attaches and releases objects (:class:`~planning.task.segments.Attach`,
:class:`~planning.task.segments.Detach`); a plan carries its scene's payload throughout. Each
object with a shape is drawn as one :class:`CarriedSpan`: from its attach to its release it
moves with its frame; before, it rests where it is taken, and after, where it is left
(:func:`carried_poses`). Headless: the viewer (:mod:`planning.viz.viewer`) draws them.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.pipeline.scene import Scene
from planning.task.holding import scene_after
from planning.task.segments import KINDS, Attach, Detach, Segment

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class CarriedSpan:
    """An object carried over part of a trajectory.

    Attributes:
        name: the object's name (its payload's).
        frame: the frame it is attached to (``None``: the robot's tool frame).
        shape: its shape, placed in the frame.
        attached_s: when the robot takes it [s].
        released_s: when it leaves it [s] (the trajectory's end where it is never released).
    """

    name: str
    frame: str | None
    shape: ck.Obstacle
    attached_s: float
    released_s: float


def carried_spans(
    start_payload: ck.Payload | None, changes: Sequence[tuple[float, ck.Payload | None]], end_s: float
) -> tuple[CarriedSpan, ...]:
    """The spans of the objects with a shape that a trajectory ending at ``end_s`` [s] carries.

    Args:
        start_payload: what it carries at its start (``None``: nothing).
        changes: ``(t, payload)`` in time order: from ``t`` [s] on it carries ``payload``
            (``None``: nothing, the object released).
        end_s: the trajectory's end [s].
    """
    spans, held, since = [], start_payload, 0.0
    for t, payload in (*changes, (end_s, None)):
        if held is not None and held.shape is not None:
            spans.append(CarriedSpan(held.name, held.frame, held.shape, since, t))
        held, since = payload, t
    return tuple(spans)


def carried_poses(
    robot: ck.Robot, trajectory: Trajectory, span: CarriedSpan, times: FloatArray
) -> FloatArray:
    """``(F, 4, 4)`` the object's shape in the world at ``times`` ``(F,)`` [s].

    Its frame's pose at the instant clipped to the span, times the shape's placement in the
    frame: it moves with the frame while carried, and rests before and after. ``robot``
    need not carry it (its frames are those of the robot without the payload).
    """
    held_at = np.clip(np.asarray(times, dtype=float), span.attached_s, span.released_s)
    frame_in_world = ck.frame_poses(robot, np.atleast_2d(trajectory(held_at)), span.frame)
    return np.asarray(frame_in_world @ span.shape.placement.homogeneous)


def recorded_scenes(
    scene: Scene,
    robot: ck.Robot,
    trajectory: Trajectory,
    task: Sequence[Segment],
    record: Sequence[Mapping[str, Any]],
) -> list[tuple[float, Scene]]:
    """A task's scene after each of its attaches and releases, ``(t, scene)`` in time order.

    ``task``: its segments in ``scene``; ``record``: the trajectory file's ``task`` list, entry
    by entry the segments' (their times ``t0`` [s]). From ``t`` on, the robot carries the
    scene's payload among its obstacles (:func:`planning.task.holding.scene_after`, ``robot``
    placing what it takes as ``trajectory`` holds it). None where the two are not one task's
    (other lengths or kinds, an attach or release the task cannot make: ``cpr-plan check``
    says why).
    """
    if len(task) != len(record):
        return []
    scenes: list[tuple[float, Scene]] = []
    for segment, entry in zip(task, record, strict=True):
        if not isinstance(segment, Attach | Detach):
            continue
        t0 = entry.get("t0")
        if entry.get("kind") != KINDS[type(segment)] or not isinstance(t0, int | float):
            return []
        try:
            scene = scene_after(scene, robot, trajectory(float(t0)), segment)
        except PlanningError:
            return []
        scenes.append((float(t0), scene))
    return scenes
