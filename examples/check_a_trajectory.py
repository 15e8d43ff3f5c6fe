"""Check someone else's trajectory file against a scene, as ``cpr-plan check`` does.

    python examples/check_a_trajectory.py

Writes a trajectory by hand (a cpr-trajectory/1 file: one septic segment per knot interval,
coefficients lowest power first, docs/formats.md), reads it back as anyone's file, and
verifies it against the scene: C3, start and goal, certified clearance, ranges and limits.
A second file with a segment moved by 2 cm fails, and says where.
"""

import json
from pathlib import Path

from planning import (
    Requirements,
    build_problem,
    paper_scene,
    plan,
    read_trajectory,
    verify_trajectory,
    write_trajectory,
)

scene = paper_scene(seed=1)
out = Path("out/examples/check")
out.mkdir(parents=True, exist_ok=True)
write_trajectory(plan(scene), out / "theirs.json")  # stands in for a file from elsewhere

document = json.loads((out / "theirs.json").read_text())
document["segments"][1]["coeffs"][1][0] += 0.02  # d2 of segment 1 raised by 2 cm: a jump at a knot
(out / "edited.json").write_text(json.dumps(document))

problem = build_problem(scene)  # the scene's robot, obstacles, start and goal
for name in ("theirs.json", "edited.json"):
    trajectory = read_trajectory(out / name).trajectory  # refuses a malformed file, naming the key
    # the scene's margins, its start and goal (a tcp or pose checked by forward kinematics),
    # and the joint torques (RNEA) within the URDF's effort limits
    verdict = verify_trajectory(problem.world, trajectory, Requirements.of(problem, endpoints=True))
    print(f"{name}: {'verified' if verdict.accepted else 'FAILS: ' + '; '.join(verdict.problems)}")
