"""A MoveIt robot state's attached collision object as the scene's ``payload``.

MoveIt attaches an object to a link (``link_name``) with the links it may touch
(``touch_links``, and the allowed-collision matrix's entries of its id) and a ``weight``
[kg]. The scene's ``payload`` is the same concept: its ``frame`` the link, its ``shape`` the
object's one primitive or mesh placed in the link's frame, its ``mass_kg`` the weight (a
point mass at the primitive's centre, or the mesh's centroid), its ``touch_links`` those
links. The request's start state attaches over the scene's robot state (the same id
replaces it). One attached object is supported; an object given in another frame than its
link's (which needs the state's kinematics to place) is refused, as are more shapes than one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
import trimesh

from cpr_kin.kinematics.dynamics import MAX_PAYLOAD_KG
from planning.io.moveit_matrix import AllowedContacts
from planning.io.moveit_messages import (
    AttachedCollisionObject,
    MotionPlanRequest,
    MoveItImportError,
    PlanningScene,
)
from planning.io.moveit_objects import convert_object


@dataclass(frozen=True)
class AttachedPayload:
    """The scene's ``payload`` entry of an attached object, and the mesh file it names, if any.

    Attributes:
        entry: the ``payload:`` mapping; ``None``: nothing is attached.
        meshes: mesh files to write beside the scene, by file name.
    """

    entry: dict[str, Any] | None = None
    meshes: dict[str, trimesh.Trimesh] = field(default_factory=dict)


def attached_objects(
    scene: PlanningScene, request: MotionPlanRequest
) -> dict[str, tuple[str, AttachedCollisionObject]]:
    """The attached objects by id, each with the field that gives it; the request's over the scene's."""
    found = {}
    for prefix, state in (
        ("scene.robot_state", scene.robot_state),
        ("request.start_state", request.start_state),
    ):
        for k, item in enumerate(state.attached_collision_objects):
            found[item.object.id] = (f"{prefix}.attached_collision_objects[{k}]", item)
    return found


def attached_payload(
    scene: PlanningScene,
    request: MotionPlanRequest,
    links: set[str],
    contacts: AllowedContacts,
    notes: list[str],
) -> AttachedPayload:
    """The ``payload`` of the one attached object, if any (module docstring).

    Args:
        scene: the planning scene.
        request: the request.
        links: the URDF's links.
        contacts: the scene's allowed-collision matrix (the links it lets the object touch).
        notes: what the conversion ignored is appended here.

    Raises:
        MoveItImportError: more than one attached object; a link, frame, weight or touch link
            that does not fit; what :func:`~planning.io.moveit_objects.convert_object` refuses.
    """
    attached = attached_objects(scene, request)
    if not attached:
        return AttachedPayload()
    if len(attached) > 1:
        given = ", ".join(where for where, _ in attached.values())
        raise MoveItImportError(
            f"{given}: {len(attached)} attached objects {sorted(attached)}; one is supported "
            "(the scene's payload)"
        )
    where, item = next(iter(attached.values()))
    if item.link_name not in links:
        raise MoveItImportError(f"{where}.link_name = '{item.link_name}' is not a link of the URDF")
    frame = item.object.header.frame_id.removeprefix("/")
    if frame not in ("", item.link_name):
        raise MoveItImportError(
            f"{where}.object.header.frame_id = '{frame}': give the attached object in its link's frame "
            f"'{item.link_name}'"
        )
    if not 0.0 <= item.weight <= MAX_PAYLOAD_KG:
        raise MoveItImportError(f"{where}.weight = {item.weight!r} kg must be in [0, {MAX_PAYLOAD_KG:g}] kg")
    unknown = sorted(set(item.touch_links) - links)
    if unknown:
        raise MoveItImportError(f"{where}.touch_links {unknown} are not links of the URDF")
    converted = convert_object(item.object, f"{where}.object ('{item.object.id}')", np.eye(4))
    if len(converted.obstacles) != 1:
        raise MoveItImportError(
            f"{where}.object has {len(converted.obstacles)} shapes; an attached object has one"
        )
    if item.detach_posture:
        notes.append(f"{where}.detach_posture (no gripper motion is planned)")
    shape = {key: value for key, value in converted.obstacles[0].items() if key != "name"}
    com = np.asarray(shape["xyz"], dtype=float)
    if shape["shape"] == "mesh":
        mesh = converted.meshes[shape["mesh"]]
        com = com + pin.rpy.rpyToMatrix(*shape["rpy"]) @ np.asarray(mesh.centroid, dtype=float)
    touching = set(item.touch_links) | contacts.allowed_with(item.object.id, links)
    entry = {
        "name": item.object.id,
        "mass_kg": float(item.weight),
        "com_in_tcp": [float(v) for v in com],
        "frame": item.link_name,
        "shape": shape,
        "touch_links": sorted(touching - {item.link_name}),
    }
    return AttachedPayload(entry=entry, meshes=converted.meshes)
