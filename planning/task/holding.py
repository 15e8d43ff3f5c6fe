"""What the robot holds from an attach or a detach on, and the world it leaves: one rule.

The planner (:func:`~planning.task.task_plan.plan_task`) and the check of its trajectory
(:func:`~planning.task.task_check.check_task`) both go from segment to segment by
:func:`scene_after`. Objects change hands with the world as MoveIt's do:

- an :class:`~planning.task.segments.Attach` whose payload has no shape and is named after an
  obstacle of the scene takes that obstacle out of the world: the robot carries its shape,
  placed in the grasping frame as it is there (:func:`cpr_kin.taken_from`); the obstacle's
  ``touch_links`` (the fingers at it) join the payload's;
- a :class:`~planning.task.segments.Detach` of an object with a shape leaves it in the world
  where it is, an obstacle of the segments after it that the links that held it may touch
  (:func:`cpr_kin.left_at`: the hand opens and leaves); an object without a shape leaves only
  its mass.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Sequence
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import PlanningError
from planning.pipeline.scene import Scene
from planning.task.segments import Attach, Detach, Segment

FloatArray = NDArray[np.float64]
_T = TypeVar("_T")


def scene_after(scene: Scene, robot: ck.Robot, q: FloatArray, change: Attach | Detach) -> Scene:
    """``scene`` from ``change`` on, with the robot at ``q`` [rad, m]: what it carries, its obstacles.

    ``robot``: the robot as loaded, carrying nothing (its frames place the object).

    Raises:
        PlanningError: a detach of nothing or of another object; an attach while carrying; an
            attach that gives a shape to an obstacle's name, or names a point cloud; an attach
            of nothing (no obstacle of its name, no shape, no mass); an object left where an
            obstacle of its name already is.
    """
    held = scene.payload
    if isinstance(change, Detach):
        if held is None:
            raise PlanningError("detach: the robot carries nothing here (attach a payload first)")
        if change.name is not None and change.name != held.name:
            raise PlanningError(
                f"detach: name = {change.name!r}, but the robot carries {held.name!r}; name it, or leave "
                "the name out"
            )
        if held.shape is None:
            return dataclasses.replace(scene, payload=None)
        if any(o.name == held.name for o in scene.obstacles):
            raise PlanningError(
                f"detach: '{held.name}' would be left in the world beside an obstacle of the same name; "
                "rename the object or the obstacle"
            )
        left = _checked(lambda: ck.left_at(robot, held, q), "detach")
        return dataclasses.replace(scene, payload=None, obstacles=(*scene.obstacles, left))
    if held is not None:
        raise PlanningError(f"attach: the robot already carries '{held.name}' (detach it first)")
    payload = change.payload
    found = next((o for o in scene.obstacles if o.name == payload.name), None)
    if found is None:
        if payload.shape is None and payload.mass_kg == 0.0:
            named = sorted(o.name for o in scene.obstacles)
            raise PlanningError(
                f"attach: '{payload.name}' is no obstacle of the scene here, and the payload has neither "
                f"a shape nor a mass: it would carry nothing; name an obstacle (here: {named}) or give "
                "'shape' or 'mass_kg'"
            )
        return dataclasses.replace(scene, payload=payload)
    taken = _checked(lambda: ck.taken_from(robot, payload, found, q), "attach")
    rest = tuple(o for o in scene.obstacles if o is not found)
    return dataclasses.replace(scene, payload=taken, obstacles=rest)


def changed_object(change: Attach | Detach, before: Scene, after: Scene) -> ck.Payload | None:
    """The object ``change`` concerns: what an attach makes the robot carry, what a detach lets go.

    ``before`` and ``after``: the scenes on either side of it (:func:`scene_after`).
    """
    return after.payload if isinstance(change, Attach) else before.payload


def checked_touches(scene: Scene, segments: Sequence[Segment]) -> None:
    """Refuse, before anything is planned, an attach whose ``touch_obstacles`` names no object of the task.

    The names a task can meet: the scene's obstacles and what its payloads leave behind. That
    the one named is there when the object is carried is checked where it is carried.

    Raises:
        PlanningError: the first attach naming an unknown obstacle, with the names known.
    """
    payloads = [scene.payload, *(s.payload for s in segments if isinstance(s, Attach))]
    known = {o.name for o in scene.obstacles} | {p.name for p in payloads if p is not None}
    for index, segment in enumerate(segments):
        if isinstance(segment, Attach):
            unknown = sorted(set(segment.payload.touch_obstacles) - known)
            if unknown:
                raise PlanningError(
                    f"task[{index}] (attach): touch_obstacles {unknown} are neither obstacles of the scene "
                    f"nor objects the task leaves; those: {sorted(known)}"
                )


def untaken(obstacles: Sequence[ck.Obstacle], carried: Iterable[ck.Payload | None]) -> list[ck.Obstacle]:
    """The ``obstacles`` that none of ``carried`` is: one a task takes is drawn as what it carries.

    (An attach that names an obstacle takes it, and no two objects share a name: the first
    attach of a name that the scene's obstacles hold takes that obstacle.)
    """
    names = {p.name for p in carried if p is not None}
    return [o for o in obstacles if o.name not in names]


def _checked(make: Callable[[], _T], kind: str) -> _T:
    """``make()``, its :class:`cpr_kin.CprKinError` as the segment's :class:`PlanningError`."""
    try:
        return make()
    except ck.CprKinError as exc:
        raise PlanningError(f"{kind}: {exc}") from None
