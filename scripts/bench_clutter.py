"""What a room's clutter out of the robot's reach costs a plan: each scene alone, among boxes, in a cloud.

    python scripts/bench_clutter.py [--robot panda] [--scenes 6] [--seed 0] [--boxes 400] [--runs 3]

Each of ``--scenes`` seeded scenes of an example arm (:func:`planning.bench.arm_scenes.blocked_scene`:
a ball across its way) is planned warm, in one process, alternated ``--runs`` times, three ways:

- ``alone``: as drawn;
- ``boxes``: with ``--boxes`` boxes of 5-40 cm (seeded) in a shell from 0.3 to 1.5 m beyond the
  robot's reach (the largest distance of its swept capsules from its base), 0 to 2 m high;
- ``room``: with a point cloud of a room's floor (2 cm below the base, the robot's footprint left
  out) and 1.2 m walls 0.2 m beyond its reach, 2 cm apart, as 3 cm voxels (a cropped camera scan).

None of the clutter can touch the robot but the floor, so every variant plans the same
trajectory (checked: the durations are printed), and what it costs more is the price of many
obstacles. Prints per scene the median warm planning time of each and the ratios to ``alone``,
then the median ratios.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time

import numpy as np

import cpr_kin as ck
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from cpr_kin.shapes.cloud_obstacles import voxel_obstacles
from planning.bench.arm_scenes import blocked_scene
from planning.cli.arguments import COUNT, SEED
from planning.io.scene_file import parse_scene
from planning.pipeline.planner import plan
from planning.pipeline.scene import MAX_OBSTACLES, Scene

VOXEL_M = 0.03
"""The room cloud's voxel side [m]."""


def reach_m(robot: ck.Robot) -> float:
    """The largest distance of the robot's swept capsules from its base's origin [m]."""
    far = 0.0
    for geometry in robot_reach(robot):
        for hull in geometry.hulls:
            centre, _, half, radius = hull.capsule()
            far = max(far, float(np.linalg.norm(centre)) + half + radius)
    return far


def boxes(count: int, reach: float, seed: int) -> list[ck.Obstacle]:
    """``count`` boxes in a shell 0.3-1.5 m beyond ``reach`` [m], 0-2 m high (seeded)."""
    rng = np.random.default_rng(seed)
    found = []
    for k in range(count):
        radius, angle = reach + rng.uniform(0.3, 1.5), rng.uniform(0.0, 2 * np.pi)
        centre = (radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 2.0))
        size, rpy = tuple(rng.uniform(0.05, 0.4, 3)), tuple(rng.uniform(-np.pi, np.pi, 3))
        found.append(ck.Obstacle.box(size, centre, rpy, name=f"clutter{k}"))
    return found


def room(reach: float) -> list[ck.Obstacle]:
    """A cloud of a room's floor and four 1.2 m walls 0.2 m beyond ``reach`` [m], as voxels."""
    half, spacing = reach + 0.2, 0.02
    side = np.arange(-half, half + 1e-9, spacing)
    height = np.arange(0.0, 1.2 + 1e-9, spacing)
    a, z = (grid.ravel() for grid in np.meshgrid(side, height))
    walls = [np.stack(w, axis=1) for w in ((0 * a - half, a, z), (0 * a + half, a, z))]
    walls += [np.stack(w, axis=1) for w in ((a, 0 * a - half, z), (a, 0 * a + half, z))]
    x, y = (grid.ravel() for grid in np.meshgrid(side, side))
    floor = np.stack([x, y, np.full(x.size, -0.02)], axis=1)[np.hypot(x, y) > 0.25]
    return voxel_obstacles(np.concatenate([*walls, floor]), VOXEL_M, "room")


def timed(scene: Scene, robot: ck.Robot) -> tuple[float, float]:
    """Warm planning time [s] and the trajectory's duration [s]."""
    start = time.perf_counter()
    result = plan(scene, robot)
    return time.perf_counter() - start, result.trajectory.duration


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", choices=sorted(EXAMPLE_ROBOTS), default="panda", help="the arm")
    parser.add_argument("--scenes", type=COUNT, default=6, help="seeded scenes (default 6)")
    parser.add_argument("--seed", type=SEED, default=0, help="seed of the first (default 0)")
    parser.add_argument("--boxes", type=COUNT, default=400, help="clutter boxes (default 400)")
    parser.add_argument("--runs", type=COUNT, default=3, help="alternated runs a scene (median; default 3)")
    args = parser.parse_args()
    robot = ck.load_robot(example_robot(args.robot))
    reach = reach_m(robot)
    clutter, cloud = boxes(args.boxes, reach, args.seed), room(reach)
    for what, count in (("--boxes", len(clutter)), (f"the room cloud of {args.robot}", len(cloud))):
        if count + 1 > MAX_OBSTACLES:  # + the scene's ball
            parser.error(
                f"{what}: {count} obstacles and a scene's ball; a scene takes at most {MAX_OBSTACLES}"
            )
    print(
        f"{args.robot} (reach {reach:.2f} m), {args.scenes} scenes from seed {args.seed}, warm, "
        f"{args.runs} runs: alone, among {len(clutter)} boxes, in a room cloud of {len(cloud)} blocks"
    )
    header = ("alone [s]", "boxes [s]", "room [s]", "boxes/alone", "room/alone")
    print(f"{'scene':<12} " + " ".join(f"{h:>9}" for h in header))
    ratios: dict[str, list[float]] = {"boxes": [], "room": []}
    for seed in range(args.seed, args.seed + args.scenes):
        document = blocked_scene(f"{args.robot}_{seed}", args.robot, robot, seed)
        alone = parse_scene(document, f"{args.robot} seed {seed}")
        variants = {
            "alone": alone,
            "boxes": dataclasses.replace(alone, obstacles=(*alone.obstacles, *clutter)),
            "room": dataclasses.replace(alone, obstacles=(*alone.obstacles, *cloud)),
        }
        if seed == args.seed:
            timed(alone, robot)  # warm-up: imports, compiled kernels
        times: dict[str, list[float]] = {name: [] for name in variants}
        durations = set()
        for _ in range(args.runs):
            for name, scene in variants.items():
                seconds, duration = timed(scene, robot)
                times[name].append(seconds)
                durations.add(round(duration, 9))
        median = {name: statistics.median(values) for name, values in times.items()}
        for name in ratios:
            ratios[name].append(median[name] / median["alone"])
        same = "" if len(durations) == 1 else f"  durations differ: {sorted(durations)}"
        print(
            f"{alone.name[:12]:<12} {median['alone']:>9.3f} {median['boxes']:>9.3f} {median['room']:>9.3f} "
            f"{ratios['boxes'][-1]:>9.2f} {ratios['room'][-1]:>9.2f}{same}"
        )
    print(
        f"median ratio to alone: boxes {statistics.median(ratios['boxes']):.2f}, "
        f"room {statistics.median(ratios['room']):.2f}"
    )


if __name__ == "__main__":
    main()
