"""Convert every MotionBenchMaker problem to a scene file and count those whose start and goal are valid.

    python scripts/import_mbm.py [--robots panda ur5] [--limit N [--sample-seed S]] [--out DIR]

Each problem goes the way a user's does: ``import-moveit`` (:func:`planning.io.moveit_import.import_moveit`
on vamp-planner 0.6.4's URDF and SRDF, margins 0 as in MoveIt), the scene file written and
read back (:func:`planning.io.scene_file.load_scene`); then its start and goal are checked
against the obstacles and the robot's own links (:func:`planning.pipeline.endpoints.margin_violation`,
on our collision model: the URDF's meshes as convex hulls where a hull is within 1 mm of its
mesh, else the exact mesh (:mod:`cpr_kin.shapes.exact_meshes`); the SRDF's and the scene's allowed
pairs). Prints per class: problems, converted, start and goal valid, and why the others are not.
``--limit N --sample-seed S`` converts N problems of each class drawn at random (the same seed,
the same problems): written with ``--out``, a held-out set for ``bench_mbm.py --scenes``.
The archive is downloaded once from PyPI and cached (:mod:`planning.bench.mbm`).
"""

from __future__ import annotations

import argparse
import collections
import re
import sys
import tempfile
import time
from pathlib import Path

import cpr_kin as ck
from planning.bench.mbm import endpoint_violations, import_problem
from planning.bench.problem_selection import add_selection, check_selection, selected_problems
from planning.errors import PlanningError
from planning.io.scene_file import load_scene


def reason(text: str) -> str:
    """A violation in a few words: which margin, and the pair (numbers left out)."""
    text = re.sub(r" q = \[[^]]*\]", "", text)  # the configuration, if given
    return re.sub(r" is -?[0-9.]+ m from", " near", text.split(" (")[0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_selection(parser)
    parser.add_argument("--out", type=Path, help="folder for the scene files (default: a temporary one)")
    args = parser.parse_args()
    check_selection(parser, args)
    out = args.out or Path(tempfile.mkdtemp(prefix="mbm-"))
    for robot_name in args.robots:
        robot: ck.Robot | None = None
        started = time.perf_counter()
        table: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)
        for problem in selected_problems(args, robot_name):
            counts = table[problem.problem_class]
            counts["problems"] += 1
            try:
                scene = load_scene(import_problem(problem, out / robot_name / f"{problem.name}.yaml"))
            except (PlanningError, ck.CprKinError) as exc:
                counts[f"not converted: {exc}"[:120]] += 1
                continue
            counts["converted"] += 1
            assert scene.robot is not None  # an imported scene names its robot
            robot = (
                robot if robot is not None and robot.joint_names == scene.robot.joints else scene.robot.load()
            )
            problems_here = [reason(text) for text in endpoint_violations(scene, robot)]
            counts["valid"] += not problems_here
            for text in problems_here:
                counts[text] += 1
        print(f"\n{robot_name}: {time.perf_counter() - started:.0f} s, scene files in {out / robot_name}")
        print(f"{'class':18s} {'problems':>8s} {'converted':>9s} {'valid':>6s}  invalid because")
        total: collections.Counter[str] = collections.Counter()
        for problem_class, counts in table.items():
            total.update(counts)
            why = [f"{k} x{v}" for k, v in counts.items() if k not in ("problems", "converted", "valid")]
            row = f"{problem_class:18s} {counts['problems']:8d} {counts['converted']:9d} {counts['valid']:6d}"
            print(f"{row}  {'; '.join(why)}")
        print(f"{'all':18s} {total['problems']:8d} {total['converted']:9d} {total['valid']:6d}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
