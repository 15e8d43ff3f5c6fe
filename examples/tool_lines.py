"""Straight tool lines from Python: a gripper's approach along its axis, and a line that breaks.

    python examples/tool_lines.py

A Panda (example-robot-data) stands above a table with a 1.5 kg part in its hand. It moves
its tool 12 cm along the tool's z axis (the approach of a grasp), then tries 80 cm straight
down, which the table stops: the error names the share of the line achieved, as MoveIt's
Cartesian path reports its fraction. Each motion is jerk- and torque-limited, at rest at both
ends, and its deviation from the line is certified at every instant, not only at samples.
"""

import numpy as np

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.errors import ToolLineBrokenError
from planning.pipeline.verification import Requirements
from planning.task import LineTolerance, ToolLine, plan_line

robot = ck.load_robot(example_robot("panda"))
table = ck.Obstacle.box(size=(0.4, 0.6, 0.05), xyz=(0.5, 0.0, 0.15), name="table")
world = ck.CollisionWorld(robot, [table])
home = robot.configuration([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # the tool points down
required = Requirements(
    margin_m=0.01,  # from the table [m]
    step_m=0.01,  # the certified check's largest robot motion between its checks [m]
    dynamics=ck.robot_dynamics(robot, ck.Payload(mass_kg=1.5)),  # torques with the part held
)
approach = ToolLine(by=(0.0, 0.0, 0.12), offset_frame="tool", tolerance=LineTolerance(position_m=5e-4))
motion = plan_line(world, home, approach, required)
print(
    f"approach: {motion.trajectory.duration:.3f} s from {np.round(motion.start.xyz, 3).tolist()} "
    f"to {np.round(motion.goal.xyz, 3).tolist()}"
)
print(
    f"certified deviation {motion.deviation.position_m * 1e3:.3f} mm, {motion.deviation.angle_rad:.2e} rad "
    f"(tolerance 0.5 mm, 0.01 rad); certified clearance {motion.verification.check.certified_min_m:.3f} m"
)
try:
    plan_line(world, home, ToolLine(by=(0.0, 0.0, -0.8), offset_frame="base"), required)
except ToolLineBrokenError as broken:
    print(f"straight down: {broken.fraction:.0%} achieved ({broken})")
