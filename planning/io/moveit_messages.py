"""MoveIt's ``PlanningScene`` and ``MotionPlanRequest`` messages as YAML, validated.

The models list every field of the messages (ROS 1 Noetic and ROS 2), so that a misspelt
or unknown key is refused by name; a number must be a number, a flag true or false. Poses
and quaternions: :mod:`planning.io.moveit_poses`. What the conversion does not support is
refused there (:mod:`planning.io.moveit_import`), never dropped.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any, TypeVar

from pydantic import BaseModel, Field, ValidationError

from cpr_kin.common.user_files import load_yaml
from planning.errors import PlanningError
from planning.io.moveit_poses import (
    Message,
    Number,
    Pose,
    Quaternion,
    Transform,
    Vector3,
)
from planning.validation import describe_validation, model_within


class Header(Message):
    """``std_msgs/Header``."""

    seq: int = 0
    stamp: dict[str, Any] = Field(default_factory=dict)
    frame_id: str = ""


class SolidPrimitive(Message):
    """``shape_msgs/SolidPrimitive``."""

    type: int | str
    dimensions: list[Number] = Field(default_factory=list)
    polygon: dict[str, Any] = Field(default_factory=dict)


class MeshTriangle(Message):
    """``shape_msgs/MeshTriangle``."""

    vertex_indices: Annotated[list[int], Field(min_length=3, max_length=3)]


class Mesh(Message):
    """``shape_msgs/Mesh``."""

    triangles: list[MeshTriangle] = Field(default_factory=list)
    vertices: list[Vector3] = Field(default_factory=list)


class CollisionObject(Message):
    """``moveit_msgs/CollisionObject``."""

    header: Header = Field(default_factory=Header)
    pose: Pose | None = None
    id: str = ""
    type: dict[str, Any] = Field(default_factory=dict)
    primitives: list[SolidPrimitive] = Field(default_factory=list)
    primitive_poses: list[Pose] = Field(default_factory=list)
    meshes: list[Mesh] = Field(default_factory=list)
    mesh_poses: list[Pose] = Field(default_factory=list)
    planes: list[dict[str, Any]] = Field(default_factory=list)
    plane_poses: list[Pose] = Field(default_factory=list)
    subframe_names: list[str] = Field(default_factory=list)
    subframe_poses: list[Pose] = Field(default_factory=list)
    operation: int | str = 0


class JointState(Message):
    """``sensor_msgs/JointState``."""

    header: Header = Field(default_factory=Header)
    name: list[str] = Field(default_factory=list)
    position: list[Number] = Field(default_factory=list)
    velocity: list[Number] = Field(default_factory=list)
    effort: list[Number] = Field(default_factory=list)


class MultiDofJointState(Message):
    """``sensor_msgs/MultiDOFJointState``."""

    header: Header = Field(default_factory=Header)
    joint_names: list[str] = Field(default_factory=list)
    transforms: list[Transform] = Field(default_factory=list)
    twist: list[dict[str, Any]] = Field(default_factory=list)
    wrench: list[dict[str, Any]] = Field(default_factory=list)


class AttachedCollisionObject(Message):
    """``moveit_msgs/AttachedCollisionObject``."""

    link_name: str
    object: CollisionObject
    touch_links: list[str] = Field(default_factory=list)
    detach_posture: dict[str, Any] = Field(default_factory=dict)
    weight: Number = 0.0


class RobotState(Message):
    """``moveit_msgs/RobotState``."""

    joint_state: JointState = Field(default_factory=JointState)
    multi_dof_joint_state: MultiDofJointState = Field(default_factory=MultiDofJointState)
    attached_collision_objects: list[AttachedCollisionObject] = Field(default_factory=list)
    is_diff: bool = False


class TransformStamped(Message):
    """``geometry_msgs/TransformStamped``."""

    header: Header = Field(default_factory=Header)
    child_frame_id: str = ""
    transform: Transform = Field(default_factory=Transform)


class AllowedCollisionMatrix(Message):
    """``moveit_msgs/AllowedCollisionMatrix``."""

    entry_names: list[str] = Field(default_factory=list)
    entry_values: list[list[bool]] = Field(default_factory=list)
    default_entry_names: list[str] = Field(default_factory=list)
    default_entry_values: list[bool] = Field(default_factory=list)


class Octomap(Message):
    """``octomap_msgs/Octomap``: ``data`` the tree's bytes (int8, or 0 to 255), ``binary`` their encoding."""

    header: Header = Field(default_factory=Header)
    binary: bool = False
    id: str = ""
    resolution: Number = 0.0
    data: list[Annotated[int, Field(ge=-128, le=255)]] = Field(default_factory=list)


class OctomapWithPose(Message):
    """``octomap_msgs/OctomapWithPose``: the tree's frame at ``origin`` in ``header.frame_id``."""

    header: Header = Field(default_factory=Header)
    origin: Pose = Field(default_factory=Pose)
    octomap: Octomap = Field(default_factory=Octomap)


class PlanningSceneWorld(Message):
    """``moveit_msgs/PlanningSceneWorld``."""

    collision_objects: list[CollisionObject] = Field(default_factory=list)
    octomap: OctomapWithPose = Field(default_factory=OctomapWithPose)


class PlanningScene(Message):
    """``moveit_msgs/PlanningScene``."""

    name: str = ""
    robot_state: RobotState = Field(default_factory=RobotState)
    robot_model_name: str = ""
    fixed_frame_transforms: list[TransformStamped] = Field(default_factory=list)
    allowed_collision_matrix: AllowedCollisionMatrix = Field(default_factory=AllowedCollisionMatrix)
    link_padding: list[dict[str, Any]] = Field(default_factory=list)
    link_scale: list[dict[str, Any]] = Field(default_factory=list)
    object_colors: list[dict[str, Any]] = Field(default_factory=list)
    world: PlanningSceneWorld = Field(default_factory=PlanningSceneWorld)
    is_diff: bool = False


class JointConstraint(Message):
    """``moveit_msgs/JointConstraint``."""

    joint_name: str
    position: Number
    tolerance_above: Number = 0.0
    tolerance_below: Number = 0.0
    weight: Number = 1.0


class BoundingVolume(Message):
    """``moveit_msgs/BoundingVolume``."""

    primitives: list[SolidPrimitive] = Field(default_factory=list)
    primitive_poses: list[Pose] = Field(default_factory=list)
    meshes: list[Mesh] = Field(default_factory=list)
    mesh_poses: list[Pose] = Field(default_factory=list)


class PositionConstraint(Message):
    """``moveit_msgs/PositionConstraint``."""

    header: Header = Field(default_factory=Header)
    link_name: str
    target_point_offset: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    constraint_region: BoundingVolume = Field(default_factory=BoundingVolume)
    weight: Number = 1.0


class OrientationConstraint(Message):
    """``moveit_msgs/OrientationConstraint``."""

    header: Header = Field(default_factory=Header)
    orientation: Quaternion = Field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])
    link_name: str
    absolute_x_axis_tolerance: Number = 0.0
    absolute_y_axis_tolerance: Number = 0.0
    absolute_z_axis_tolerance: Number = 0.0
    parameterization: int = 0
    weight: Number = 1.0


class Constraints(Message):
    """``moveit_msgs/Constraints``."""

    name: str = ""
    joint_constraints: list[JointConstraint] = Field(default_factory=list)
    position_constraints: list[PositionConstraint] = Field(default_factory=list)
    orientation_constraints: list[OrientationConstraint] = Field(default_factory=list)
    visibility_constraints: list[dict[str, Any]] = Field(default_factory=list)


class MotionPlanRequest(Message):
    """``moveit_msgs/MotionPlanRequest``."""

    workspace_parameters: dict[str, Any] = Field(default_factory=dict)
    start_state: RobotState = Field(default_factory=RobotState)
    goal_constraints: list[Constraints] = Field(default_factory=list)
    path_constraints: Constraints = Field(default_factory=Constraints)
    trajectory_constraints: dict[str, Any] = Field(default_factory=dict)
    reference_trajectories: list[dict[str, Any]] = Field(default_factory=list)
    pipeline_id: str = ""
    planner_id: str = ""
    group_name: str = ""
    num_planning_attempts: int = 0
    allowed_planning_time: Number = 0.0
    max_velocity_scaling_factor: Number = 0.0
    max_acceleration_scaling_factor: Number = 0.0
    cartesian_speed_end_effector_link: str = ""
    cartesian_speed_limited_link: str = ""
    max_cartesian_speed: Number = 0.0


MAX_MESSAGE_BYTES = 50_000_000
"""Largest MoveIt message file read [bytes]."""
Model = TypeVar("Model", bound=BaseModel)


class MoveItImportError(PlanningError):
    """A MoveIt file holds what the conversion does not support, or is inconsistent."""


def read_message(path: Path, model: type[Model]) -> Model:
    """The message of the YAML file ``path``, validated by ``model``; errors name the file and field.

    An unknown key lists the keys allowed in the (nested) message that holds it; a file that
    holds nothing (empty, or only comments) is refused: it is not a message.
    """
    what = f"MoveIt {model.__name__} file"
    data = load_yaml(Path(path), MAX_MESSAGE_BYTES, what)
    if data is None:
        raise MoveItImportError(f"{what} '{path}' is empty; it must hold a {model.__name__} message")
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        raise MoveItImportError(f"{path}: {describe_validation(exc, model_within(model))}") from None
