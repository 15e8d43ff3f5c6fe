"""A ``MotionPlanRequest``'s goal as a scene file's goal entry.

One ``Constraints`` set: joint constraints on every planned joint become ``q`` (at their
positions; the tolerances are met exactly); one position constraint, whose region is a
sphere or a box, becomes a ``tcp`` goal at the region's centre with the sphere's radius or
the box's smallest half side as ``tolerance_m``; with an orientation constraint on the same
link, a ``pose`` goal whose ``tolerance_rad`` is the smallest axis tolerance. The link named
becomes the tool frame.
"""

from __future__ import annotations

from typing import Any

from planning.io.moveit_messages import MotionPlanRequest, MoveItImportError


def goal_entry(request: MotionPlanRequest, planned: tuple[str, ...]) -> tuple[dict[str, Any], str | None]:
    """The scene file's goal entry of ``request``, and the tool frame a pose goal names (module docstring).

    Raises:
        MoveItImportError: not exactly one constraint set, or constraints with no counterpart.
    """
    if len(request.goal_constraints) != 1:
        raise MoveItImportError(
            f"request.goal_constraints holds {len(request.goal_constraints)} sets; exactly one is supported"
        )
    goal = request.goal_constraints[0]
    if goal.visibility_constraints:
        raise MoveItImportError("request.goal_constraints[0].visibility_constraints are not supported")
    if goal.joint_constraints:
        if goal.position_constraints or goal.orientation_constraints:
            raise MoveItImportError("a goal of joint and pose constraints together is not supported")
        values = {c.joint_name: c.position for c in goal.joint_constraints}
        missing, extra = sorted(set(planned) - set(values)), sorted(set(values) - set(planned))
        if missing or extra:
            raise MoveItImportError(
                f"the goal's joint constraints must name every planned joint {list(planned)}: "
                f"missing {missing}, not planned {extra}"
            )
        return {"q": {name: values[name] for name in planned}}, None
    if len(goal.position_constraints) != 1 or len(goal.orientation_constraints) > 1:
        raise MoveItImportError(
            f"the goal has {len(goal.position_constraints)} position and {len(goal.orientation_constraints)} "
            "orientation constraints; supported: one position constraint, with at most one orientation one"
        )
    position = goal.position_constraints[0]
    region = position.constraint_region
    if any(position.target_point_offset) or len(region.primitives) != 1 or region.meshes:
        raise MoveItImportError(
            "a position constraint needs a zero target_point_offset and a region of one primitive"
        )
    centre = region.primitive_poses[0].position if region.primitive_poses else [0.0, 0.0, 0.0]
    dimensions = region.primitives[0].dimensions
    kind = region.primitives[0].type
    tolerance = (
        dimensions[0] if kind in (2, "sphere") else min(dimensions) / 2 if kind in (1, "box") else None
    )
    if tolerance is None or tolerance <= 0:
        raise MoveItImportError(f"a position constraint's region must be a sphere or a box, not {kind!r}")
    if not goal.orientation_constraints:
        return {"tcp": list(centre), "tolerance_m": tolerance}, position.link_name
    orientation = goal.orientation_constraints[0]
    if orientation.link_name != position.link_name:
        raise MoveItImportError(
            f"position and orientation constraints on different links "
            f"('{position.link_name}', '{orientation.link_name}') are not supported"
        )
    axes = (orientation.absolute_x_axis_tolerance, orientation.absolute_y_axis_tolerance)
    tolerance_rad = min((*axes, orientation.absolute_z_axis_tolerance))
    pose = {"xyz": list(centre), "quat_xyzw": list(orientation.orientation)}
    return {
        "pose": pose,
        "tolerance_m": tolerance,
        "tolerance_rad": max(tolerance_rad, 1e-6),
    }, position.link_name
