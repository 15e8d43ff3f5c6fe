"""A script's loop of ``plan(load_scene(path))``: each robot kept between calls, against loaded each call.

    python scripts/bench_library_loop.py [--robots cpr panda ur5 so101] [--scenes 3] [--rounds 5]

For each robot, ``--scenes`` seeded scenes of :func:`planning.bench.arm_scenes.blocked_scene`
(the CPR: its bundled shelf and paper scenes) are written as scene files, then planned warm in
one process as a user's script plans them, ``plan(load_scene(path))``, with no robot passed:

- ``kept``: the robot :func:`cpr_kin.shared_robot` keeps (what ``plan`` does);
- ``loaded``: the same call after :func:`cpr_kin.forget_shared_robots`, so that every plan loads
  its robot again (what ``plan`` did before the robots were kept).

The two alternate call by call, ``--rounds`` times over the scenes. It prints each robot's
median wall time of a call both ways and their ratio, and checks that both give the same
trajectories.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

import cpr_kin as ck
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from planning import load_scene, plan, warm_up
from planning.bench.arm_scenes import blocked_scene
from planning.cli.arguments import COUNT
from planning.io.bundled import bundled_scene_paths


def scene_files(robot: str, count: int, folder: Path) -> list[Path]:
    """``count`` scene files of ``robot`` (the CPR's bundled ones, else seeded blocked scenes)."""
    if robot == "cpr":
        return [p for p in bundled_scene_paths() if p.stem in ("shelf", "paper")][:count]
    loaded = ck.load_robot(example_robot(robot))
    paths = []
    for seed in range(count):
        path = folder / f"{robot}_{seed}.yaml"
        path.write_text(yaml.safe_dump(blocked_scene(path.stem, robot, loaded, seed, self_clearance_m=0.005)))
        paths.append(path)
    return paths


def main() -> int:
    """Run the loop (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    robots = ["cpr", *sorted(EXAMPLE_ROBOTS)]
    parser.add_argument("--robots", nargs="+", default=["cpr", "panda", "ur5", "so101"], choices=robots)
    parser.add_argument("--scenes", type=COUNT, default=3, help="scenes per robot (default: 3)")
    parser.add_argument("--rounds", type=COUNT, default=5, help="passes over the scenes (default: 5)")
    args = parser.parse_args()
    warm_up()
    with tempfile.TemporaryDirectory() as folder:
        files = {robot: scene_files(robot, args.scenes, Path(folder)) for robot in args.robots}
        print(f"plan(load_scene(path)) warm, {args.rounds} rounds, alternated call by call")
        print("| robot | scenes | kept: median call [s] | loaded each call: median [s] | kept / loaded |")
        print("|---|---|---|---|---|")
        same = True
        for robot, paths in files.items():
            for path in paths:  # kernels and caches warm for this robot before it is timed
                plan(load_scene(path))
            spent: dict[str, list[float]] = {"kept": [], "loaded": []}
            for round_ in range(args.rounds):
                for index, path in enumerate(paths):
                    order = ("kept", "loaded") if (round_ + index) % 2 == 0 else ("loaded", "kept")
                    trajectories = []
                    for way in order:
                        if way == "loaded":
                            ck.forget_shared_robots()
                        started = time.perf_counter()
                        trajectories.append(plan(load_scene(path)).trajectory.coefficients)
                        spent[way].append(time.perf_counter() - started)
                    same &= bool(np.array_equal(trajectories[0], trajectories[1]))
            kept, loaded = statistics.median(spent["kept"]), statistics.median(spent["loaded"])
            print(f"| {robot} | {len(paths)} | {kept:.3f} | {loaded:.3f} | {kept / loaded:.2f} |")
    print("the same trajectories both ways" if same else "TRAJECTORIES DIFFER between the two ways")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
