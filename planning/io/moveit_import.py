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
  tolerance) as a ``tcp`` or ``pose`` goal.
- **Obstacles:** :mod:`planning.io.moveit_objects`; in the URDF root's frame, or a frame of
  ``fixed_frame_transforms``.
- **Allowed collisions:** the matrix's robot-link pairs marked ``true``.
- **Time:** ``allowed_planning_time`` (when > 0) becomes the planner's ``time_limit_s`` (at
  most :data:`~planning.pipeline.settings.MAX_TIME_LIMIT_S`).

What would change the problem and has no counterpart (attached objects, path or trajectory
constraints, an octomap, padding, velocity scaling other than 0 or 1, a robot base placed
away from the world's origin, allowed contact with an object) is refused naming it; what only
steers MoveIt's own planner (planner id, pipeline, attempts, workspace) is listed as ignored.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
import yaml
from lxml import etree

import cpr_kin as ck
from cpr_kin.limits import MAX_LIMITS_BYTES
from cpr_kin.packages import check_package_dirs
from cpr_kin.srdf_groups import group_joints
from cpr_kin.urdf_file import parse_urdf
from cpr_kin.user_files import load_yaml
from planning.io.moveit_goal import goal_entry
from planning.io.moveit_messages import Constraints, MotionPlanRequest, MoveItImportError, PlanningScene
from planning.io.moveit_objects import convert_object
from planning.io.moveit_state import joint_values, position_ranges, within_ranges, wrapped
from planning.io.publish import write_file
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
        document: the scene file's document (absolute paths; :func:`write_imported` makes
            them relative to the file).
        meshes: mesh files the obstacles name, by file name.
        ignored: what the conversion left out or adjusted, each in a few words.
    """

    document: dict[str, Any]
    meshes: dict[str, trimesh.Trimesh] = field(default_factory=dict)
    ignored: tuple[str, ...] = ()


def _refuse_unsupported(scene: PlanningScene, request: MotionPlanRequest) -> list[str]:
    """Raise on content without a counterpart; return what is ignored."""
    refusals = {
        "scene.robot_state.attached_collision_objects": scene.robot_state.attached_collision_objects,
        "request.start_state.attached_collision_objects": request.start_state.attached_collision_objects,
        "scene.world.octomap": scene.world.octomap.get("octomap", {}).get("data"),
        "scene.link_padding": [p for p in scene.link_padding if p.get("padding", 0.0) != 0.0],
        "scene.link_scale": [s for s in scene.link_scale if s.get("scale", 1.0) != 1.0],
        "request.path_constraints": request.path_constraints != Constraints(),
        "request.trajectory_constraints": request.trajectory_constraints.get("constraints"),
        "request.reference_trajectories": request.reference_trajectories,
    }
    for key, value in refusals.items():
        if value:
            raise MoveItImportError(f"{key} is not supported; remove it from the file")
    for key in ("max_velocity_scaling_factor", "max_acceleration_scaling_factor"):
        if getattr(request, key) not in (0.0, 1.0):
            raise MoveItImportError(
                f"request.{key} = {getattr(request, key)}: scaling is not supported (0 or 1: the full "
                "limits); scale the limits file instead"
            )
    for state in (scene.robot_state, request.start_state):
        for transform in state.multi_dof_joint_state.transforms:
            if not np.allclose(transform.matrix(), np.eye(4), atol=1e-9):
                raise MoveItImportError(
                    f"a robot base placed at {transform.translation} in the world is not supported; "
                    "give the objects in the robot's base frame"
                )
    ignored = [
        f"request.{key}"
        for key in ("planner_id", "pipeline_id", "num_planning_attempts")
        if getattr(request, key)
    ]
    return ignored + (["request.workspace_parameters"] if request.workspace_parameters else [])


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
    ignored = _refuse_unsupported(scene, request)
    tree = parse_urdf(robot.urdf)
    check_package_dirs(robot.urdf, robot.package_dirs)
    if robot.limits is not None:  # a file that is not there or not YAML is named now, not at planning
        load_yaml(robot.limits, MAX_LIMITS_BYTES, "joint limits file")
    root = _root_link(tree)
    planned = (
        group_joints(robot.srdf, request.group_name, tree).joints
        if robot.srdf is not None and request.group_name
        else replace(ck.robot_spec(robot.urdf), package_dirs=robot.package_dirs).load().joint_names
    )
    goal, tcp = goal_entry(request, planned)
    movable = {j.get("name", "") for j in tree.getroot().findall("joint") if j.get("type") != "fixed"}
    continuous = {j.get("name", "") for j in tree.getroot().findall("joint") if j.get("type") == "continuous"}
    ranges = position_ranges(tree)
    values = within_ranges(
        wrapped(joint_values(scene.robot_state, request.start_state), continuous), ranges, ignored
    )
    if "q" in goal:
        goal = {**goal, "q": within_ranges(wrapped(goal["q"], continuous), ranges, ignored)}
    missing = [j for j in planned if j not in values]
    if missing:
        raise MoveItImportError(f"the start state gives no value for the planned joint(s) {missing}")
    not_moving = sorted(set(values) - movable)
    if not_moving:
        ignored.append(
            f"start values of {len(not_moving)} joint(s) the URDF does not move ({', '.join(not_moving)})"
        )
    frames = {"": np.eye(4), root: np.eye(4)}
    for stamped in scene.fixed_frame_transforms:
        if stamped.header.frame_id not in ("", root):
            raise MoveItImportError(f"fixed frame '{stamped.child_frame_id}' is given in another frame")
        frames[stamped.child_frame_id] = stamped.transform.matrix()
    obstacles: list[dict[str, Any]] = []
    meshes: dict[str, trimesh.Trimesh] = {}
    for k, obj in enumerate(scene.world.collision_objects):
        where = f"scene.world.collision_objects[{k}] ('{obj.id}')"
        if obj.header.frame_id not in frames:
            raise MoveItImportError(
                f"{where}: frame '{obj.header.frame_id}' is not the robot's base '{root}'"
            )
        converted = convert_object(obj, where, frames[obj.header.frame_id])
        obstacles += converted.obstacles
        meshes.update(converted.meshes)
    links = {link.get("name", "") for link in tree.getroot().findall("link")}
    objects = {obj.id for obj in scene.world.collision_objects}
    matrix = scene.allowed_collision_matrix
    unknown = sorted((set(matrix.entry_names) | set(matrix.default_entry_names)) - links - objects)
    if unknown:
        ignored.append(f"allowed-collision entries of {unknown}, neither links of the URDF nor objects")
    robot_entry: dict[str, Any] = {"urdf": str(robot.urdf), "joints": list(planned)}
    robot_entry |= {"srdf": str(robot.srdf)} if robot.srdf else {}
    robot_entry |= {"packages": [str(d) for d in robot.package_dirs]} if robot.package_dirs else {}
    robot_entry |= {"limits": str(robot.limits)} if robot.limits else {}
    robot_entry |= {"tcp": tcp} if tcp else {}
    held = {j: v for j, v in values.items() if j in movable and j not in planned}
    robot_entry |= {"fixed": held} if held else {}
    document: dict[str, Any] = {
        "name": name,
        "robot": robot_entry,
        "safety_margin": margins_m[0],
        "self_margin": margins_m[1],
        "allowed_collisions": _allowed(scene, links, objects),
        "start": {"q": {j: values[j] for j in planned}},
        "goal": goal,
        "obstacles": obstacles,
    }
    if request.allowed_planning_time > 0:
        document["planner"] = {"time_limit_s": min(float(request.allowed_planning_time), MAX_TIME_LIMIT_S)}
    return ImportedScene(document=document, meshes=meshes, ignored=tuple(ignored))


def _root_link(tree: etree._ElementTree) -> str:
    children = {
        j.find("child").get("link") for j in tree.getroot().findall("joint") if j.find("child") is not None
    }
    roots = [
        link.get("name", "") for link in tree.getroot().findall("link") if link.get("name") not in children
    ]
    return roots[0] if roots else ""


def _allowed(scene: PlanningScene, links: set[str], objects: set[str]) -> list[list[str]]:
    """The allowed-collision matrix's robot-link pairs; contact with an object is refused.

    Entries of names that are neither links nor objects change nothing (as in MoveIt); the
    caller lists them as ignored.
    """
    matrix = scene.allowed_collision_matrix
    names = matrix.entry_names
    if len(matrix.entry_values) != len(names) or any(len(row) != len(names) for row in matrix.entry_values):
        raise MoveItImportError(
            f"allowed_collision_matrix: {len(names)} names need a {len(names)} x {len(names)} matrix"
        )
    pairs = {
        tuple(sorted((names[i], names[j])))
        for i in range(len(names))
        for j in range(i + 1, len(names))
        if matrix.entry_values[i][j] or matrix.entry_values[j][i]
    }
    for name, value in zip(matrix.default_entry_names, matrix.default_entry_values, strict=False):
        if value:
            pairs |= {tuple(sorted((name, link))) for link in links if link != name}
    touching = sorted(p for p in pairs if (p[0] in objects) != (p[1] in objects))
    if touching:
        raise MoveItImportError(
            f"allowed_collision_matrix allows {list(touching[0])} to touch; "
            "contact with an object is not supported"
        )
    return [list(p) for p in sorted(pairs) if p[0] in links and p[1] in links]


def write_imported(imported: ImportedScene, out: Path) -> Path:
    """Write the scene file ``out`` and its meshes (``<stem>_meshes/``), paths relative to ``out``.

    The scene is validated (:func:`~planning.io.scene_file.parse_scene`) before its file is
    written; if it is refused, the meshes written for it are removed and nothing is left.

    Raises:
        SceneError: the converted scene is not a valid scene (a size beyond the allowed range, say).
    """
    from planning.io.scene_file import parse_scene

    out = Path(out)
    folder = out.parent.resolve()
    document = dict(imported.document)

    def relative(path: str) -> str:
        return os.path.relpath(path, folder)

    robot = dict(document["robot"])
    for key in ("urdf", "srdf", "limits"):
        if key in robot:
            robot[key] = relative(robot[key])
    if "packages" in robot:
        robot["packages"] = [relative(p) for p in robot["packages"]]
    document["robot"] = robot
    mesh_folder = f"{out.stem}_meshes"
    obstacles = []
    for obstacle in document["obstacles"]:
        if obstacle["shape"] == "mesh":
            obstacle = {**obstacle, "mesh": f"{mesh_folder}/{obstacle['mesh']}"}
        obstacles.append(obstacle)
    document["obstacles"] = obstacles
    written = [
        write_file(folder / mesh_folder / file, bytes(trimesh.exchange.stl.export_stl(mesh)))
        for file, mesh in imported.meshes.items()
    ]
    try:
        parse_scene(document, source=str(out), base=folder)
    except Exception:
        for path in written:
            path.unlink(missing_ok=True)
        if written and not any((folder / mesh_folder).iterdir()):
            (folder / mesh_folder).rmdir()
        raise
    return write_file(out, yaml.safe_dump(document, sort_keys=False, default_flow_style=None, width=100))
