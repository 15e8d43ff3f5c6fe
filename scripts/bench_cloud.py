"""A scene's obstacles as a point cloud beside the same scene with its primitives: planning time, certified.

Each scene (the shelf of ``examples/scenes/``, and ``--scenes`` generated CPR scenes) is planned
twice in one warm process, alternated ``--runs`` times: with its primitives, and with a cloud of
``--points`` points sampled on their surfaces (``cpr_kin.shapes.cloud_obstacles.sampled_surfaces``) as
``--resolution`` voxels. Prints, per scene, the median warm planning time of each, their ratio
(cloud / primitives), and whether both trajectories were certified; then the median ratio.
Target (issue 69): the cloud at most 3x the primitives.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

import cpr_kin as ck
from cpr_kin.shapes.cloud_obstacles import sampled_surfaces, voxel_obstacles
from planning.bench.scene_generator import generate_scenes
from planning.cli.arguments import COUNT, SEED, number_above
from planning.errors import NoSolutionError
from planning.io.scene_file import load_scene
from planning.pipeline.planner import plan
from planning.pipeline.scene import Scene

SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


def timed(scene: Scene, robot: ck.Robot) -> tuple[float, bool]:
    """Warm planning time [s] and whether a certified trajectory came out."""
    start = time.perf_counter()
    try:
        result = plan(scene, robot)
    except NoSolutionError:
        return time.perf_counter() - start, False
    return time.perf_counter() - start, result.metrics.min_clearance_m >= scene.safety_margin


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", type=COUNT, default=10, help="generated CPR scenes (default 10)")
    parser.add_argument("--seed", type=SEED, default=0, help="their generator's seed (default 0)")
    parser.add_argument("--points", type=COUNT, default=100_000, help="points a cloud (default 100000)")
    parser.add_argument("--resolution", type=number_above(0.0, "m"), default=0.01, help="voxel side [m]")
    parser.add_argument("--runs", type=COUNT, default=3, help="alternated runs a scene (median; default 3)")
    args = parser.parse_args()
    robot = ck.load_cpr()
    scenes = [load_scene(SHELF), *generate_scenes(args.scenes, args.seed, robot)]
    plan(scenes[0], robot)  # warm-up: imports, compiled kernels
    print(
        f"{len(scenes)} scenes, clouds of {args.points} points as {args.resolution:g} m voxels, "
        f"warm, {args.runs} runs"
    )
    print(f"{'scene':<12} {'blocks':>6} {'primitives [s]':>14} {'cloud [s]':>10} {'ratio':>6}  certified")
    ratios = []
    for index, scene in enumerate(scenes):
        cloud = voxel_obstacles(
            sampled_surfaces(scene.obstacles, args.points, index), args.resolution, "cloud"
        )
        as_cloud = dataclasses.replace(scene, obstacles=tuple(cloud))
        times: dict[str, list[float]] = {"primitives": [], "cloud": []}
        certified = True
        for _ in range(args.runs):
            for kind, variant in (("primitives", scene), ("cloud", as_cloud)):
                seconds, ok = timed(variant, robot)
                times[kind].append(seconds)
                certified &= ok
        primitives, clouded = statistics.median(times["primitives"]), statistics.median(times["cloud"])
        ratios.append(clouded / primitives)
        print(
            f"{scene.name[:12]:<12} {len(cloud):>6} {primitives:>14.3f} {clouded:>10.3f} "
            f"{ratios[-1]:>6.2f}  {certified}"
        )
    print(f"median ratio cloud / primitives: {statistics.median(ratios):.2f} (target <= 3)")


if __name__ == "__main__":
    main()
