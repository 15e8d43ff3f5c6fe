"""Plan a scene file from Python, print what a user checks first, and write the trajectory.

    python examples/plan_a_scene.py [SCENE] [OUT]

SCENE defaults to ``examples/scenes/shelf.yaml``, OUT to ``out/examples/plan``.
"""

import sys
from pathlib import Path

from planning import load_scene, plan, write_trajectory

HERE = Path(__file__).resolve().parent

scene = load_scene(sys.argv[1] if len(sys.argv) > 1 else HERE / "scenes" / "shelf.yaml")
result = plan(scene)  # seeded search -> septic spline -> timing -> certified check
metrics = result.metrics
print(f"{scene.name}: {metrics.duration_s:.3f} s, timed '{metrics.timing}'")
print(f"certified clearance {metrics.min_clearance_m:.4f} m >= margin {scene.safety_margin} m")
print(f"peak velocity, acceleration, jerk / limit: {metrics.limit_utilisation}")
out = Path(sys.argv[2] if len(sys.argv) > 2 else "out/examples/plan")
out.mkdir(parents=True, exist_ok=True)
write_trajectory(result, out / "trajectory.json")  # cpr-trajectory/1 (docs/formats.md)
print(f"wrote {out / 'trajectory.json'}")
