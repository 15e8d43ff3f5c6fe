"""Plan for a robot of your own from Python: a URDF (+ SRDF), a pose goal, a checked trajectory.

    python examples/bring_your_own_robot.py

The robot is example-robot-data's Panda; for yours, give ``RobotSpec`` your files
(``urdf``, ``srdf``, ``package_dirs``, ``limits``) and a start of yours. What is not given is
found by the rules of ``cpr_kin.RobotSpec``: the planned joints, the tool frame, the SRDF.
"""

import numpy as np

import cpr_kin as ck
from cpr_kin.packages import example_robot
from planning import Scene, Target, dump_scene, plan, write_trajectory

spec = ck.RobotSpec(urdf=example_robot("panda"))  # e.g. RobotSpec("arm.urdf", srdf="arm.srdf")
robot = spec.load()  # URDF + SRDF + meshes (package://) -> kinematics, collision hulls, self pairs
print(f"joints {list(robot.joint_names)}, tool '{robot.tcp_frame}', held {dict(robot.held)}")

start = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])  # [rad] the Panda's ready pose
start_tool = ck.frame_poses(robot, start[None])[0]  # (4, 4) pose of the tool in the base frame
goal_position = start_tool[:3, 3] + [0.0, 0.4, -0.1]  # 40 cm sideways, 10 cm down, same orientation
ball = ck.Obstacle.sphere(0.05, tuple(start_tool[:3, 3] + [0.0, 0.2, -0.05]), name="ball")  # on the way
scene = Scene(
    robot=spec,
    start=Target(q=tuple(start)),
    goal=Target(pose=(tuple(goal_position), tuple(map(tuple, start_tool[:3, :3])))),
    obstacles=(ball,),
    safety_margin=0.02,
    name="sideways",
)
result = plan(scene, robot)  # IK (verified) -> search -> septic spline -> timing -> certified check
end = result.trajectory(result.trajectory.knots[-1:])[0]  # the last instant's joint values
print(
    f"duration {result.metrics.duration_s:.3f} s, certified clearance {result.metrics.min_clearance_m:.4f} m"
)
print(f"goal met by forward kinematics: {scene.goal.miss(robot, end) is None}")
dump_scene(scene, "sideways.yaml")  # the scene file: `cpr-plan plan sideways.yaml` plans it again
write_trajectory(result, "sideways.json")  # cpr-trajectory/1
print("wrote sideways.yaml, sideways.json; verify with: cpr-plan check sideways.yaml sideways.json")
