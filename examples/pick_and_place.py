"""A pick and place as one task: move, lower the tool, grasp, lift, carry, release, rise.

    python examples/pick_and_place.py                                            # the CPR
    python examples/pick_and_place.py examples/scenes/panda_pick_and_place.yaml  # a Panda

``examples/scenes/pick_and_place.yaml`` holds the task: the CPR among the shelf's obstacles
moves above the part (an obstacle of the scene that the tool may touch), lowers the tool 8 cm
on a straight line, waits while the gripper closes, attaches the part (taken from the world:
its 1.5 kg in the torques, its shape in the checks from there on), lifts it straight back up,
carries it to the far side, releases it (an obstacle again, where it is left) and rises
clear. Each segment starts where the one before ends, at rest; the whole trajectory is C3
(jerk continuous), within every joint limit and torque, its clearance certified along its
whole length, and each line's deviation certified at every instant. ``cpr-plan plan`` plans
the same file from the shell. ``panda_pick_and_place.yaml`` does the same with a Panda: it takes
a can from a stand and sets it down until it stands on a table (the can may touch both).
"""

import sys
from pathlib import Path

from planning.io.scene_file import load_scene_file
from planning.task import check_task, plan_task, task_record

scene = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "scenes" / "pick_and_place.yaml"
read = load_scene_file(scene)
task = plan_task(read.scene, read.task)
for segment in task.segments:
    line = "" if segment.line is None else f", {segment.line.deviation.position_m * 1e3:.3f} mm off its line"
    print(f"{segment.kind:6s} {segment.t0:6.3f} -> {segment.t1:6.3f} s{line}")
duration, clearance = task.trajectory.duration, task.certified_min_clearance_m
print(f"task: {duration:.3f} s, verified {task.accepted}, certified clearance {clearance:.3f} m")
# what the trajectory file's `task` list holds, checked as `cpr-plan check` checks it
checked = check_task(read.scene, read.task, task.trajectory, task_record(task))
print(f"its record checked against the task: {'kept' if checked.accepted else checked.problems}")
