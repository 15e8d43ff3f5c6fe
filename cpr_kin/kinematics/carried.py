"""A robot carrying its payload's collision shape: an attached object, checked like the robot's own links.

:func:`carrying` returns a new :class:`~cpr_kin.Robot` whose collision model (and visual
model, for the viewer) holds the payload's shape attached to its frame, in the ``effector``
group: every clearance query, the certified checks (its motion radii included) and the
self-collision pairs then see it. Its self pairs follow the URDF rule: against every link
but those on its own joint and the joint next to it (the hand that holds it), and but its
``touch_links`` (the fingers that grip it, as MoveIt's attached objects): :func:`holding_links`.

An object changes hands with the world as MoveIt's do: :func:`taken_from` makes an obstacle the
payload (its shape placed in the frame that grasps it), :func:`left_at` makes a payload's shape
an obstacle where the robot lets it go, one that its holding links may touch (the fingers open
around it and leave).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from cpr_kin.collision.srdf_pairs import adjacent
from cpr_kin.common.errors import CprKinError
from cpr_kin.kinematics.dynamics import PAYLOAD_NAME, Payload
from cpr_kin.kinematics.forward import frame_poses
from cpr_kin.model.robot import Robot, RobotGeometry
from cpr_kin.shapes.obstacles import Obstacle

PAYLOAD_GEOMETRY = PAYLOAD_NAME
"""Name of the payload's collision geometry unless the payload has a name of its own."""
PAYLOAD_COLOR = np.array([0.9, 0.6, 0.1, 0.8])
"""RGBA colour of the payload's shape in the viewer."""


def carrying(robot: Robot, payload: Payload | None) -> Robot:
    """``robot`` with ``payload``'s collision shape on its frame; ``robot`` itself without one.

    A mesh shape is its convex hull, as the robot's own link meshes are.

    Raises:
        CprKinError: the payload's frame, or a link it may touch, is not the robot's.
    """
    if payload is None or payload.shape is None:
        return robot
    frame_id = robot.frame_id(payload.frame_on(robot))
    robot.check_links(payload.touch_links, "payload touch_links")
    collision = robot.collision_model.copy()
    shape = _hull(payload.shape)
    index = collision.addGeometryObject(_shape_object(robot, shape, payload.name, frame_id))
    held_by = holding_links(robot, payload)
    pairs = [(g.index, index) for g in robot.geometries if g.link not in held_by]
    build_visual = robot.build_visual_model

    def visual_model() -> Any:
        visual = build_visual().copy()
        visual.addGeometryObject(_shape_object(robot, shape, payload.name, frame_id))
        return visual

    link = robot.model.frames[frame_id].name
    held = RobotGeometry(payload.name, link, "effector", index, carried=True, touches=payload.touch_obstacles)
    return dataclasses.replace(
        robot,
        collision_model=collision,
        build_visual_model=visual_model,
        geometries=(*robot.geometries, held),
        _data=robot.model.createData(),
        self_pairs=tuple(sorted((*robot.self_pairs, *pairs))),
    )


def holding_links(robot: Robot, payload: Payload) -> frozenset[str]:
    """Links that may touch ``payload``'s shape: on its frame's joint and the next; its ``touch_links``."""
    joint = robot.model.frames[robot.frame_id(payload.frame_on(robot))].parentJoint
    objects = robot.collision_model.geometryObjects
    near = {g.link for g in robot.geometries if adjacent(robot.model, objects[g.index].parentJoint, joint)}
    return frozenset(near | set(payload.touch_links))


def left_at(robot: Robot, payload: Payload, q: ArrayLike) -> Obstacle:
    """``payload``'s shape as an obstacle where it is with the robot at ``q`` [rad, m], named after it.

    Its :func:`holding_links` may touch it (the hand that let it go); a mesh is its convex hull,
    as it was carried.

    Raises:
        CprKinError: the payload has no shape (nothing is left), or a frame not the robot's.
    """
    if payload.shape is None:
        raise CprKinError(f"payload '{payload.name}' has no shape to leave in the world")
    frame_in_world = frame_poses(robot, q, payload.frame_on(robot))
    shape_in_world = pin.SE3(frame_in_world) * payload.shape.placement
    return dataclasses.replace(
        _hull(payload.shape),
        name=payload.name,
        xyz=shape_in_world.translation,
        rpy=pin.rpy.matrixToRpy(shape_in_world.rotation),
        touch_links=tuple(sorted(holding_links(robot, payload))),
    )


def taken_from(robot: Robot, payload: Payload, obstacle: Obstacle, q: ArrayLike) -> Payload:
    """``payload`` with ``obstacle``'s shape, placed in its frame as it is with the robot at ``q``.

    The obstacle's ``touch_links`` join the payload's (the fingers at the part it grasps).

    Raises:
        CprKinError: the payload has a shape of its own, or the obstacle is a point cloud.
    """
    if payload.shape is not None:
        raise CprKinError(
            f"payload '{payload.name}' has a shape, and obstacle '{obstacle.name}' another; a payload "
            "taken from the world takes the obstacle's: leave out its shape"
        )
    if obstacle.shape == "voxels":
        raise CprKinError(f"obstacle '{obstacle.name}' is a point cloud's voxels; only shapes can be carried")
    frame_in_world = frame_poses(robot, q, payload.frame_on(robot))
    shape_in_frame = pin.SE3(frame_in_world).actInv(obstacle.placement)
    shape = dataclasses.replace(
        obstacle,
        xyz=shape_in_frame.translation,
        rpy=pin.rpy.matrixToRpy(shape_in_frame.rotation),
        touch_links=(),
    )
    links = tuple(dict.fromkeys((*payload.touch_links, *obstacle.touch_links)))
    return dataclasses.replace(payload, shape=shape, touch_links=links)


def _hull(shape: Obstacle) -> Obstacle:
    """``shape`` as a carried object is checked: a mesh by its convex hull."""
    return dataclasses.replace(shape, convex=True) if shape.shape == "mesh" else shape


def _shape_object(robot: Robot, shape: Obstacle, name: str, frame_id: int) -> Any:
    """``shape`` (placed in frame ``frame_id``) as a ``GeometryObject`` ``name`` on the frame's joint."""
    frame = robot.model.frames[frame_id]
    found = pin.GeometryObject(
        name, frame.parentJoint, frame_id, frame.placement * shape.placement, shape.geometry()
    )
    found.meshColor = PAYLOAD_COLOR
    return found
