"""Write seeded scenes for any arm (a ball across its way) as scene files, for ``bench_mbm.py --scenes``.

    python scripts/generate_arm_scenes.py --robot ur10 --count 10 --seed 0 --out out/arms/ur10
    python scripts/generate_arm_scenes.py --robot path/to/pr2.urdf --tcp r_gripper_tool_frame ...
    python scripts/generate_arm_scenes.py --robot path/to/baxter.urdf --tcp left_gripper
        --srdf path/to/baxter_manipulation.srdf ...   (an SRDF its name does not find)

The scenes of :func:`planning.bench.arm_scenes.blocked_scene`, seeds ``--seed`` to
``--seed + --count - 1``, named ``<robot>_<seed>``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import yaml

import cpr_kin as ck
from cpr_kin.model.packages import EXAMPLE_ROBOTS
from planning.bench.arm_scenes import blocked_scene
from planning.cli.arguments import COUNT, SEED, add_package_dirs, number_above, number_at_least
from planning.errors import PlanningError
from planning.io.robot_entry import BUNDLED, robot_spec_of


def main() -> int:
    """Write the scenes (module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--robot",
        required=True,
        help=f"a URDF path, '{BUNDLED}' (the bundled CPR) or one of {sorted(EXAMPLE_ROBOTS)}",
    )
    parser.add_argument("--tcp", help="its tool frame (the planned joints: those from the root to it)")
    parser.add_argument(
        "--srdf",
        type=Path,
        help="its SRDF (default: found by name beside the URDF or in its package's srdf folder)",
    )
    parser.add_argument(
        "--limits",
        type=Path,
        help="its velocity, acceleration and jerk limits file (default: found beside the URDF)",
    )
    add_package_dirs(parser)
    parser.add_argument("--count", type=COUNT, default=10, help="number of scenes (default: 10)")
    parser.add_argument("--seed", type=SEED, default=0, help="seed of the first scene (default: 0)")
    parser.add_argument(
        "--margin", type=number_at_least(0.0, "m"), default=0.02, help="safety margin [m] (default: 0.02)"
    )
    parser.add_argument(
        "--self-clearance",
        type=number_above(0.0, "m"),
        default=0.02,
        help="least distance of the robot's own pairs at start and goal [m] (default: 0.02)",
    )
    parser.add_argument("--out", type=Path, required=True, help="folder for the scene files")
    args = parser.parse_args()
    named = args.robot == BUNDLED or args.robot in EXAMPLE_ROBOTS  # a scene's robot: names them too
    entry: str | dict[str, Any] = args.robot if named else str(Path(args.robot).resolve())
    srdf = None if args.srdf is None else args.srdf.resolve()
    limits = None if args.limits is None else args.limits.resolve()
    packages = [str(d.resolve()) for d in args.package_dir]
    given = {"tcp": args.tcp, "srdf": srdf, "limits": limits}
    options: dict[str, Any] = {key: str(value) for key, value in given.items() if value}
    if packages:
        options["packages"] = packages
    if options:
        entry = {"urdf": entry, **options}
    try:
        urdf = robot_spec_of(args.robot, Path.cwd()).urdf  # a name as a scene's robot: reads it
        robot = ck.load_robot(urdf, tcp=args.tcp, srdf=srdf, limits=limits, package_dirs=packages)
        stem = args.robot if named else Path(urdf).stem
        documents = [  # all drawn before any is written: a scene that cannot be drawn leaves no files
            blocked_scene(f"{stem}_{seed}", entry, robot, seed, args.margin, args.self_clearance)
            for seed in range(args.seed, args.seed + args.count)
        ]
    except (ck.CprKinError, PlanningError) as exc:
        print(f"generate_arm_scenes: {exc}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    for document in documents:
        (args.out / f"{document['name']}.yaml").write_text(yaml.safe_dump(document, sort_keys=False))
    print(f"wrote {args.count} scenes into {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
