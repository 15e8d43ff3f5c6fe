"""A pick and place as one task from Python: move, lower the tool, grasp, lift, carry.

    python examples/pick_and_place.py

The CPR among the shelf's obstacles (``examples/scenes/shelf.yaml``): a free motion to above
the part, a straight line 8 cm down, a wait while the gripper closes, a straight line back up,
and a free motion to the scene's goal. Each segment starts where the one before ends, at
rest; the whole trajectory is C3 (jerk continuous), within every joint limit, its clearance
certified along its whole length, and each line's deviation certified at every instant.
Attaching the part (its mass and shape from the grasp on) and a scene file's ``task:`` are
still to come (issue 71).
"""

from pathlib import Path

from planning.io.scene_file import load_scene
from planning.pipeline.target import Target
from planning.task import Move, ToolLine, Wait, plan_task

scene = load_scene(Path(__file__).parent / "scenes" / "shelf.yaml")
task = plan_task(
    scene,
    [
        Move(Target(tcp=(-0.1, 0.55, 0.45))),  # above the part [m]
        ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base"),  # 8 cm straight down [m]
        Wait(0.3),  # the gripper closes [s]
        ToolLine(by=(0.0, 0.0, 0.08), offset_frame="base"),
        Move(scene.goal),
    ],
)
for segment in task.segments:
    line = "" if segment.line is None else f", {segment.line.deviation.position_m * 1e3:.3f} mm off its line"
    print(f"{segment.kind:5s} {segment.t0:6.3f} -> {segment.t1:6.3f} s{line}")
verified, duration = task.verification, task.trajectory.duration
clearance = verified.check.certified_min_m
print(f"task: {duration:.3f} s, verified {verified.accepted}, certified clearance {clearance:.3f} m")
