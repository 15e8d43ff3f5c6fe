"""A ``MotionPlanRequest``'s goal as a scene file's goal entry.

One ``Constraints`` set: joint constraints on every planned joint become ``q`` (at their
positions; the tolerances are met exactly); one position constraint, whose region is a
sphere or a box, becomes a ``tcp`` goal at the region's centre with the sphere's radius or
the box's smallest half side as ``tolerance_m``; with an orientation constraint on the same
link, a ``pose`` goal whose ``tolerance_rad`` is the smallest axis tolerance. The link named
becomes the tool frame.

Each constraint is given in its header's frame, which must be fixed to the world
(:class:`~planning.io.moveit_frames.Frames`): the region's centre and the orientation are
moved into the robot's base frame. A tolerance wider than a scene's goal takes is narrowed
to the widest it takes (a goal within it meets the constraint too), and said.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from cpr_kin.common.names import repeated
from planning.io.moveit_frames import Frames
from planning.io.moveit_messages import MotionPlanRequest, MoveItImportError
from planning.io.moveit_poses import rotation_matrix
from planning.pipeline.target import TOLERANCE_M_RANGE, TOLERANCE_RAD_RANGE

GOAL = "request.goal_constraints[0]"


def _joint_goal(request: MotionPlanRequest, planned: tuple[str, ...]) -> dict[str, Any]:
    goal = request.goal_constraints[0]
    if goal.position_constraints or goal.orientation_constraints:
        raise MoveItImportError(f"{GOAL}: a goal of joint and pose constraints together is not supported")
    twice = repeated([c.joint_name for c in goal.joint_constraints])
    if twice:
        raise MoveItImportError(f"{GOAL}.joint_constraints constrain {twice} more than once; each joint once")
    values = {c.joint_name: c.position for c in goal.joint_constraints}
    missing, extra = sorted(set(planned) - set(values)), sorted(set(values) - set(planned))
    if missing or extra:
        raise MoveItImportError(
            f"{GOAL}.joint_constraints must name every planned joint {list(planned)}: "
            f"missing {missing}, not planned {extra}"
        )
    return {"q": {name: values[name] for name in planned}}


def _region_tolerance(kind: int | str, dimensions: list[float], where: str) -> float:
    """The radius of the largest sphere about the centre within a sphere or box region [m]."""
    if kind in (2, "sphere") and len(dimensions) == 1:
        if not dimensions[0] > 0:
            raise MoveItImportError(f"{where}.dimensions = {dimensions}: a sphere's radius must be > 0 m")
        return dimensions[0]
    if kind in (1, "box") and len(dimensions) == 3:
        if not min(dimensions) > 0:
            raise MoveItImportError(f"{where}.dimensions = {dimensions}: a box's sides must be > 0 m")
        return min(dimensions) / 2
    raise MoveItImportError(
        f"{where}: type {kind!r} with dimensions {dimensions}; a goal region must be a sphere (2, [radius]) "
        "or a box (1, [x, y, z])"
    )


def _narrowed(value: float, bounds: tuple[float, float], name: str, unit: str, notes: list[str]) -> float:
    low, high = bounds
    if value > high:
        notes.append(
            f"the goal's {name} {value:g} {unit} narrowed to {high:g} {unit}, the widest a scene takes"
        )
    return min(max(value, low), high)


def goal_entry(
    request: MotionPlanRequest, planned: tuple[str, ...], frames: Frames, notes: list[str]
) -> tuple[dict[str, Any], str | None]:
    """The scene file's goal entry of ``request``, and the tool frame a pose goal names (module docstring).

    Args:
        request: the request.
        planned: the planned joints.
        frames: the world-fixed frames a constraint may be given in.
        notes: what the conversion adjusted is appended here.

    Raises:
        MoveItImportError: not exactly one constraint set, constraints with no counterpart, a
            region that is no sphere or box, a frame that moves or is not known.
    """
    if len(request.goal_constraints) != 1:
        raise MoveItImportError(
            f"request.goal_constraints holds {len(request.goal_constraints)} sets; exactly one is supported"
        )
    goal = request.goal_constraints[0]
    if goal.visibility_constraints:
        raise MoveItImportError(f"{GOAL}.visibility_constraints are not supported")
    if goal.joint_constraints:
        return _joint_goal(request, planned), None
    if len(goal.position_constraints) != 1 or len(goal.orientation_constraints) > 1:
        raise MoveItImportError(
            f"{GOAL} has {len(goal.position_constraints)} position and {len(goal.orientation_constraints)} "
            "orientation constraints; supported: one position constraint, with at most one orientation one"
        )
    where = f"{GOAL}.position_constraints[0]"
    position = goal.position_constraints[0]
    region = position.constraint_region
    if any(position.target_point_offset) or len(region.primitives) != 1 or region.meshes:
        raise MoveItImportError(
            f"{where}: a position constraint needs a zero target_point_offset and a region of one primitive"
        )
    tolerance = _region_tolerance(
        region.primitives[0].type, region.primitives[0].dimensions, f"{where}.constraint_region.primitives[0]"
    )
    tolerance = _narrowed(tolerance, TOLERANCE_M_RANGE, "position tolerance", "m", notes)
    centre_in_frame = region.primitive_poses[0].position if region.primitive_poses else [0.0, 0.0, 0.0]
    frame_in_base = frames.pose(position.header.frame_id, f"{where}.header.frame_id")
    centre = [float(v) for v in frame_in_base[:3, :3] @ centre_in_frame + frame_in_base[:3, 3]]
    if not goal.orientation_constraints:
        return {"tcp": centre, "tolerance_m": tolerance}, position.link_name
    where = f"{GOAL}.orientation_constraints[0]"
    orientation = goal.orientation_constraints[0]
    if orientation.link_name != position.link_name:
        raise MoveItImportError(
            f"{where}.link_name = '{orientation.link_name}' differs from the position constraint's "
            f"'{position.link_name}'; constraints on different links are not supported"
        )
    axes = (
        orientation.absolute_x_axis_tolerance,
        orientation.absolute_y_axis_tolerance,
        orientation.absolute_z_axis_tolerance,
    )
    tolerance_rad = _narrowed(min(axes), TOLERANCE_RAD_RANGE, "orientation tolerance", "rad", notes)
    frame_in_base = frames.pose(orientation.header.frame_id, f"{where}.header.frame_id")
    rotation = frame_in_base[:3, :3] @ rotation_matrix(orientation.orientation)
    quaternion = pin.Quaternion(np.asarray(rotation)).normalized()
    pose = {"xyz": centre, "quat_xyzw": [float(v) for v in quaternion.coeffs()]}  # coeffs: x, y, z, w
    return {
        "pose": pose,
        "tolerance_m": tolerance,
        "tolerance_rad": max(tolerance_rad, 1e-6),
    }, position.link_name
