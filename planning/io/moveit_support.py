"""What of a MoveIt problem has no counterpart in a scene file: refused by name, or listed as ignored.

Refused, because it would change the problem: padding and
scaling of links, path and trajectory constraints, reference trajectories, velocity or
acceleration scaling other than 0 or 1 (the full limits), a robot base placed away from the
world's origin. Listed as ignored, because only MoveIt's own planner reads it: the planner id,
the pipeline, the number of attempts, the workspace bounds.
"""

from __future__ import annotations

import numpy as np

from planning.io.moveit_messages import Constraints, MotionPlanRequest, MoveItImportError, PlanningScene


def refuse_unsupported(scene: PlanningScene, request: MotionPlanRequest) -> list[str]:
    """What is ignored, each in a few words (module docstring).

    Raises:
        MoveItImportError: naming the first field that would change the problem.
    """
    refusals = {
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
