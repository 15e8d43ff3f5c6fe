"""Write seeded random scenes as scene files (for ``cpr-plan batch`` and the benchmarks)."""

from __future__ import annotations

import argparse
from pathlib import Path

from planning.bench.narrow_passages import ALL_KINDS, KINDS
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SEED
from planning.errors import PlanningError
from planning.io.scene_file import dump_scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--count", type=COUNT, default=100, help="number of scenes (default: 100)")
    parser.add_argument("--seed", type=SEED, default=0, help="seed of the generator (default: 0)")
    parser.add_argument(
        "--narrow",
        type=int,
        default=0,
        help="of which narrow passages, of --kinds in turn (default: 0)",
    )
    parser.add_argument(
        "--kinds",
        nargs="+",
        choices=ALL_KINDS,
        default=list(KINDS),
        help=f"the narrow passages' kinds (default: {' '.join(KINDS)}; all: {' '.join(ALL_KINDS)})",
    )
    parser.add_argument("--out", type=Path, required=True, help="folder for the scene files")
    args = parser.parse_args()
    try:
        scenes = generate_scenes(args.count, args.seed, narrow=args.narrow, kinds=args.kinds)
    except PlanningError as error:
        parser.error(str(error))
    for scene in scenes:
        dump_scene(scene, args.out / f"{scene.name}.yaml")
    print(f"wrote {args.count} scenes into {args.out}")


if __name__ == "__main__":
    main()
