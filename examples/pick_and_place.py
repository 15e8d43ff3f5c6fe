"""A pick and place as one task from Python: move, lower the tool, grasp, lift, carry, release.

    python examples/pick_and_place.py

The CPR among the shelf's obstacles (``examples/scenes/shelf.yaml``): a free motion to above
the part, a straight line 8 cm down, a wait while the gripper closes, the part attached (its
1.5 kg in the torques, its shape in the checks from there on), a straight line back up, a free
motion to the scene's goal, the part released. Each segment starts where the one before ends,
at rest; the whole trajectory is C3 (jerk continuous), within every joint limit and torque,
its clearance certified along its whole length, and each line's deviation certified at every
instant. A scene file's ``task:`` is still to come (issue 71).
"""

from pathlib import Path

import cpr_kin as ck
from planning.io.scene_file import load_scene
from planning.pipeline.target import Target
from planning.task import Attach, Detach, Move, ToolLine, Wait, plan_task

scene = load_scene(Path(__file__).parent / "scenes" / "shelf.yaml")
task = plan_task(
    scene,
    [
        Move(Target(tcp=(-0.1, 0.55, 0.45))),  # above the part [m]
        ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base"),  # 8 cm straight down [m]
        Wait(0.3),  # the gripper closes [s]
        Attach(ck.Payload(mass_kg=1.5, shape=ck.Obstacle.box(size=(0.04, 0.04, 0.04), xyz=(0, 0, 0.03)))),
        ToolLine(by=(0.0, 0.0, 0.08), offset_frame="base"),
        Move(scene.goal),
        Detach(),
    ],
)
for segment in task.segments:
    line = "" if segment.line is None else f", {segment.line.deviation.position_m * 1e3:.3f} mm off its line"
    print(f"{segment.kind:6s} {segment.t0:6.3f} -> {segment.t1:6.3f} s{line}")
duration, clearance = task.trajectory.duration, task.certified_min_clearance_m
print(f"task: {duration:.3f} s, verified {task.accepted}, certified clearance {clearance:.3f} m")
