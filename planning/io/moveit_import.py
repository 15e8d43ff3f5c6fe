"""A MoveIt ``PlanningScene`` and ``MotionPlanRequest`` as a scene file that ``cpr-plan plan`` runs.

- **Robot:** the URDF (+ SRDF, package folders, limits file) given; the planned joints are the
  request's ``group_name`` in the SRDF, the tool frame the link a pose goal names.
- **Start:** the scene's robot state, with the request's start state over it; values of joints
  the URDF holds go to ``fixed``; values of joints the URDF does not move are listed as ignored.
  Continuous joints' values are wrapped, values a hair beyond a range moved onto it and listed
  (:mod:`planning.io.moveit_state`).
- **Goal:** one ``Constraints``: joint constraints on every planned joint (``q``), or a position
  constraint (a sphere or box region: its centre, and its radius or smallest half side as the
  tolerance) with or without an orientation constraint on the same link (the smallest axis
  tolerance) as a ``tcp`` or ``pose`` goal (:mod:`planning.io.moveit_goal`).
- **Frames:** a pose is given in a frame fixed to the world: the URDF's root, a link fixed to
  it, the SRDF's virtual joint's parent (``world``), a ``fixed_frame_transforms`` child, an
  object's id; one that moves with the robot, or is unknown, is refused
  (:mod:`planning.io.moveit_frames`). An orientation of all zeros is the identity, as in MoveIt.
- **Obstacles:** :mod:`planning.io.moveit_objects`, at most
  :data:`~planning.pipeline.scene.MAX_OBSTACLES`; object ids unique.
- **Allowed collisions:** the matrix's robot-link pairs marked ``true``; a link allowed to touch a
  world object is in that object's obstacles' ``touch_links``, a world object the attached one
  may touch in the payload's ``touch_obstacles`` (:mod:`planning.io.moveit_matrix`).
- **Time:** ``allowed_planning_time`` (when > 0) becomes the planner's ``time_limit_s`` (at
  most :data:`~planning.pipeline.settings.MAX_TIME_LIMIT_S`).

- **Attached object:** the robot state's one attached collision object becomes the scene's
  ``payload`` (:mod:`planning.io.moveit_attached`).

What would change the problem and has no counterpart (path or trajectory constraints,
padding, velocity scaling other than 0 or 1, a robot base placed away from the world's origin)
is refused naming it; what only steers MoveIt's own planner (planner id, pipeline, attempts,
workspace) is listed as ignored (:mod:`planning.io.moveit_support`).
:mod:`planning.io.moveit_write` writes the result.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import trimesh

import cpr_kin as ck
from cpr_kin.collision.srdf_pairs import parse_srdf
from cpr_kin.description.srdf_groups import group_joints
from cpr_kin.description.supported import checked_urdf
from cpr_kin.model.limits import read_limits_file
from cpr_kin.model.packages import check_package_dirs
from planning.io.moveit_attached import attached_payload
from planning.io.moveit_frames import Frames
from planning.io.moveit_goal import goal_entry
from planning.io.moveit_matrix import AllowedContacts
from planning.io.moveit_messages import (
    MotionPlanRequest,
    MoveItImportError,
    PlanningScene,
)
from planning.io.moveit_objects import ConvertedObject, convert_object, obstacle_names
from planning.io.moveit_octomap import convert_octomap
from planning.io.moveit_poses import Pose, zero_quaternions
from planning.io.moveit_state import joint_values, position_ranges, within_ranges, wrapped
from planning.io.moveit_support import refuse_unsupported
from planning.pipeline.scene import MAX_OBSTACLES
from planning.pipeline.settings import MAX_TIME_LIMIT_S


@dataclass(frozen=True)
class RobotFiles:
    """The robot's files, as ``import-moveit`` takes them.

    Attributes:
        urdf: its URDF.
        srdf: its SRDF (groups and ``disable_collisions``), or ``None``.
        package_dirs: folders holding the packages its ``package://`` meshes name.
        limits: its acceleration and jerk limits file, or ``None`` (found, or defaults).
    """

    urdf: Path
    srdf: Path | None = None
    package_dirs: tuple[Path, ...] = ()
    limits: Path | None = None


@dataclass(frozen=True)
class ImportedScene:
    """A converted MoveIt problem.

    Attributes:
        document: the scene file's document (absolute paths; :mod:`~planning.io.moveit_write` makes
            them relative to the file).
        meshes: mesh files the obstacles name, by file name.
        ignored: what the conversion left out or adjusted, each in a few words.
        files: other files the obstacles name (an octomap's), by file name.
    """

    document: dict[str, Any]
    meshes: dict[str, trimesh.Trimesh] = field(default_factory=dict)
    ignored: tuple[str, ...] = ()
    files: dict[str, bytes] = field(default_factory=dict)


def convert_objects(
    scene: PlanningScene, frames: Frames, touching: Mapping[str, Collection[str]] | None = None
) -> ConvertedObject:
    """The obstacles of every collision object, in the base frame; each object's id becomes a frame.

    ``touching``: the links that may touch each object, by id (its obstacles' ``touch_links``).

    Raises:
        MoveItImportError: an id given twice, an object in a frame that moves or is unknown,
            what :func:`~planning.io.moveit_objects.convert_object` refuses, more than
            :data:`~planning.pipeline.scene.MAX_OBSTACLES` obstacles.
    """
    obstacles: list[dict[str, Any]] = []
    meshes: dict[str, trimesh.Trimesh] = {}
    ids: dict[str, int] = {}
    for k, obj in enumerate(scene.world.collision_objects):
        where = f"scene.world.collision_objects[{k}] ('{obj.id}')"
        if obj.id in ids:
            raise MoveItImportError(
                f"{where}.id: collision_objects[{ids[obj.id]}] has the same id; ids must be unique"
            )
        ids[obj.id] = k
        frame_in_base = frames.pose(obj.header.frame_id, f"{where}.header.frame_id")
        converted = convert_object(obj, where, frame_in_base)
        clash = sorted(set(converted.meshes) & set(meshes))
        if clash:
            raise MoveItImportError(
                f"{where}: its mesh file {clash[0]} is another object's; rename the object"
            )
        links = sorted((touching or {}).get(obj.id, ()))
        obstacles += [{**entry, "touch_links": links} if links else entry for entry in converted.obstacles]
        meshes.update(converted.meshes)
        if obj.id not in frames.fixed:  # MoveIt names an object's frame by its id
            frames.fixed[obj.id] = frame_in_base @ (obj.pose or Pose()).matrix()
    if len(obstacles) > MAX_OBSTACLES:
        raise MoveItImportError(
            f"scene.world.collision_objects make {len(obstacles)} obstacles; "
            f"a scene holds at most {MAX_OBSTACLES}"
        )
    return ConvertedObject(obstacles=tuple(obstacles), meshes=meshes)


def import_moveit(
    scene: PlanningScene,
    request: MotionPlanRequest,
    robot: RobotFiles,
    name: str,
    margins_m: tuple[float, float],
) -> ImportedScene:
    """The scene file of a MoveIt problem (module docstring); ``margins_m``: safety and self margins [m].

    Raises:
        MoveItImportError: unsupported or inconsistent content, naming it.
        cpr_kin.UrdfError: the robot's files do not load.
    """
    ignored = refuse_unsupported(scene, request)
    ignored += [
        f"{where} of all zeros read as the identity (as MoveIt does)"
        for where in zero_quaternions(scene, "scene") + zero_quaternions(request, "request")
    ]
    tree = checked_urdf(robot.urdf)  # as the loader reads it: the frames and ranges are read below
    model_name = tree.getroot().get("name", "")
    if scene.robot_model_name and scene.robot_model_name != model_name:  # MoveIt warns, and goes on
        ignored.append(
            f"scene.robot_model_name '{scene.robot_model_name}' is not the URDF's robot '{model_name}'"
        )
    check_package_dirs(robot.urdf, robot.package_dirs)
    if robot.limits is not None:  # a file that is not there, or no limits file, is named now
        read_limits_file(robot.limits)
    if robot.srdf is not None and request.group_name:
        planned = group_joints(robot.srdf, request.group_name, tree).joints
    else:  # the URDF was checked above: not validated twice
        spec = replace(ck.robot_spec(robot.urdf), package_dirs=robot.package_dirs, validate=False)
        planned = ck.shared_robot(spec).joint_names  # a folder of imports loads it once
    if request.group_name and robot.srdf is None:
        ignored.append(
            f"request.group_name '{request.group_name}' (no SRDF to look it up in): planned {planned}"
        )
    frames = Frames.of_urdf(tree)
    if robot.srdf is not None:
        frames.add_virtual_joints(parse_srdf(robot.srdf))
    frames.add_transforms(scene.fixed_frame_transforms)
    links = {link.get("name", "") for link in tree.getroot().findall("link")}
    matrix = scene.allowed_collision_matrix
    contacts = AllowedContacts(matrix)  # the matrix read once, for every object
    touching = {o.id: contacts.allowed_with(o.id, links) for o in scene.world.collision_objects}
    converted = convert_objects(scene, frames, touching)
    obstacles, meshes = list(converted.obstacles), converted.meshes
    octomap = convert_octomap(scene.world.octomap, frames, ignored)
    if octomap is not None:
        obstacles.append(octomap.entry)
    if not obstacles:
        ignored.append("no collision objects and no octomap in the PlanningScene: the scene has no obstacles")
    goal, tcp = goal_entry(request, planned, frames, ignored)
    joints = tree.getroot().findall("joint")
    movable = {j.get("name", "") for j in joints if j.get("type") != "fixed"}
    continuous = {j.get("name", "") for j in joints if j.get("type") == "continuous"}
    mimics = {j.get("name", "") for j in joints if j.find("mimic") is not None}
    ranges = position_ranges(tree)
    values = within_ranges(
        wrapped(joint_values(scene.robot_state, request.start_state), continuous, notes=ignored),
        ranges,
        ignored,
    )
    if "q" in goal:
        goal = {**goal, "q": within_ranges(wrapped(goal["q"], continuous, values, ignored), ranges, ignored)}
    missing = [j for j in planned if j not in values]
    if missing:
        raise MoveItImportError(f"the start state gives no value for the planned joint(s) {missing}")
    not_moving = sorted(set(values) - movable)
    if not_moving:
        ignored.append(
            f"start values of {len(not_moving)} joint(s) the URDF does not move ({', '.join(not_moving)})"
        )
    following = sorted(set(values) & mimics - set(planned))
    if following:  # MoveIt sets a mimic joint from its leader, whatever the state says
        ignored.append(f"start values of mimic joint(s) {following}: each follows the joint it mimics")
    objects = {obj.id for obj in scene.world.collision_objects}
    payload = attached_payload(scene, request, links, contacts, ignored)
    clash = sorted(set(payload.meshes) & set(meshes))
    if clash:
        raise MoveItImportError(f"the attached object's mesh file {clash[0]} is a world object's; rename one")
    meshes |= payload.meshes
    attached = {payload.entry["name"]} if payload.entry else set()
    if payload.entry is not None:  # the world objects it may touch: the payload's touch_obstacles
        allowed = contacts.allowed_with(payload.entry["name"], objects)
        names = [n for o in scene.world.collision_objects if o.id in allowed for n in obstacle_names(o)]
        if names:
            payload.entry["touch_obstacles"] = sorted(names)
    unknown = sorted((set(matrix.entry_names) | set(matrix.default_entry_names)) - links - objects - attached)
    if unknown:
        ignored.append(f"allowed-collision entries of {unknown}, neither links of the URDF nor objects")
    held = {j: v for j, v in values.items() if j in movable - mimics and j not in planned}
    robot_entry = _robot_entry(robot, planned, tcp, held)
    document: dict[str, Any] = {
        "name": name,
        "robot": robot_entry,
        "safety_margin": margins_m[0],
        "self_margin": margins_m[1],
        "allowed_collisions": contacts.link_pairs(links),
        "start": {"q": {j: values[j] for j in planned}},
        "goal": goal,
        "obstacles": obstacles,
    }
    if payload.entry is not None:
        document["payload"] = payload.entry
    if request.allowed_planning_time > 0:
        document["planner"] = {"time_limit_s": min(float(request.allowed_planning_time), MAX_TIME_LIMIT_S)}
    files = {} if octomap is None else octomap.files
    return ImportedScene(document=document, meshes=meshes, ignored=tuple(ignored), files=files)


def _robot_entry(
    robot: RobotFiles, planned: tuple[str, ...], tcp: str | None, held: dict[str, float]
) -> dict[str, Any]:
    """The scene's ``robot:`` mapping, with absolute paths (made relative when written)."""
    entry: dict[str, Any] = {"urdf": str(robot.urdf), "joints": list(planned)}
    entry |= {"srdf": str(robot.srdf)} if robot.srdf else {}
    entry |= {"packages": [str(d) for d in robot.package_dirs]} if robot.package_dirs else {}
    entry |= {"limits": str(robot.limits)} if robot.limits else {}
    entry |= {"tcp": tcp} if tcp else {}
    return entry | ({"fixed": held} if held else {})
