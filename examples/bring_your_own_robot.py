"""Plan for a robot of your own from Python: a URDF (+ SRDF), a pose goal, a checked trajectory.

    python examples/bring_your_own_robot.py [panda | ur5 | so101 | xarm7]

The robot is one of example-robot-data's arms (default: the Panda); for yours, give
``RobotSpec`` your files (``urdf``, ``srdf``, ``package_dirs``, ``limits``) and a start of
yours. What is not given is found by the rules of ``cpr_kin.RobotSpec``: the planned joints,
the tool frame, the SRDF. The goal is the tool's pose after turning the first joint by
1.2 rad, given as a pose (the IK finds a configuration for it), with a ball on the way; the
search has 30 s (``time_limit_s``: past it the plan returns what it verified, or says why not).
"""

import sys

import numpy as np

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning import PlannerSettings, Scene, Target, dump_scene, plan, write_trajectory

HOMES = {  # a start of each arm [rad]: its maker's ready pose, or one above the table
    "panda": [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785],
    "ur5": [0.0, -1.2, 1.5, -1.9, -1.57, 0.0],
    "so101": [0.0, -0.5, 0.5, 1.0, 0.0],
    "xarm7": [0.0, -0.3, 0.0, 0.6, 0.0, 0.9, 0.0],
}
name = sys.argv[1] if len(sys.argv) > 1 else "panda"
spec = ck.RobotSpec(urdf=example_robot(name))  # e.g. ck.RobotSpec("arm.urdf", srdf="arm.srdf")
robot = spec.load()  # URDF + SRDF + meshes (package://) -> kinematics, collision hulls, self pairs
print(f"{name}: joints {list(robot.joint_names)}, tool '{robot.tcp_frame}', held {dict(robot.held)}")

start = np.array(HOMES[name])
turned = np.array([start, start])
turned[:, 0] += [1.2, 0.6]  # the first joint turned by 1.2 rad, and halfway
tools = ck.frame_poses(robot, turned[:2])  # (2, 4, 4) poses of the tool frame in the base frame
goal_position, goal_rotation = tools[0, :3, 3], tools[0, :3, :3]
gap = float(np.linalg.norm(goal_position - ck.frame_poses(robot, start[None])[0, :3, 3]))  # [m]
ball = ck.Obstacle.sphere(0.15 * gap, tuple(tools[1, :3, 3]), name="ball")  # where the tool would pass
scene = Scene(
    robot=spec,
    start=Target(q=tuple(start)),
    goal=Target(pose=(tuple(goal_position), tuple(map(tuple, goal_rotation)))),
    obstacles=(ball,),
    safety_margin=0.01,
    planner=PlannerSettings(time_limit_s=30.0),  # a time budget, as MoveIt's allowed_planning_time
    name=f"{name}_turn",
)
result = plan(scene, robot)  # IK (verified) -> search -> septic spline -> timing -> certified check
end = result.trajectory(result.trajectory.knots[-1:])[0]  # the last instant's joint values
print(
    f"duration {result.metrics.duration_s:.3f} s, certified clearance {result.metrics.min_clearance_m:.4f} m"
)
print(f"goal met by forward kinematics: {scene.goal.miss(robot, end) is None}")
dump_scene(scene, f"{name}_turn.yaml")  # the scene file: `cpr-plan plan` plans it again
write_trajectory(result, f"{name}_turn.json")  # cpr-trajectory/1
print(f"wrote {name}_turn.yaml, {name}_turn.json; verify: cpr-plan check {name}_turn.yaml {name}_turn.json")
