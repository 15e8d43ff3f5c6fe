"""Inspect a plan's clearance: the certified bound, the closest pair, each collision group over time.

    python examples/inspect_clearance.py

Plans the paper case, then asks the collision world directly: coal's signed distances per
group at samples of the trajectory, and the certified continuous check the planner used.
"""

import numpy as np

import cpr_kin as ck
from planning import paper_scene, plan

result = plan(paper_scene(seed=0))
world, trajectory = result.problem.world, result.trajectory
check = result.verification  # the certified continuous check of the whole trajectory
print(f"certified clearance {check.certified_min_m:.4f} m over {len(check.times)} checks")
print(f"closest at t = {check.worst_time:.2f} s: {check.worst_pair} ({check.worst_group})")

times = np.linspace(0.0, trajectory.duration, 9)
clearance = world.clearance_batch(trajectory(times)).clearance_m  # (9, 2) [m], per group
for t, (effector, links) in zip(times, clearance, strict=True):
    print(f"t = {t:4.2f} s  effector {effector:6.3f} m  links {links:6.3f} m")

# the same check by hand, on a straight swing that hits the crate
swing = ck.check_segment(world, result.problem.q_start, result.problem.q_goal, margin_m=0.1)
print(f"the straight swing: accepted {swing.accepted}, certified {swing.certified_min_m:.3f} m")
