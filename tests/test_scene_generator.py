from __future__ import annotations

import numpy as np

import cpr_kin as ck
from planning.io.scene_file import parse_scene, scene_document
from planning.io.scene_generator import generate_scenes


def test_generated_scenes_are_reproducible_and_valid(robot: ck.Robot) -> None:
    scenes = generate_scenes(25, seed=7, robot=robot)
    assert [s.name for s in scenes] == [f"scene_{i:03d}" for i in range(25)]
    assert generate_scenes(25, seed=7, robot=robot) == scenes
    assert generate_scenes(25, seed=8, robot=robot) != scenes
    counts = {len(s.obstacles) for s in scenes}
    assert counts <= {1, 2, 3, 4, 5} and len(counts) >= 3
    shapes = {o.shape for s in scenes for o in s.obstacles}
    assert shapes == {"box", "sphere", "cylinder", "capsule"}
    for index, scene in enumerate(scenes):
        assert scene.planner.seed == index
        q = np.array([scene.start.configuration(robot), scene.goal.configuration(robot)])
        world = ck.CollisionWorld(robot, scene.obstacles)
        assert world.clearance_batch(q).min_clearance_m.min() >= scene.safety_margin
        assert abs(q[1, 0] - q[0, 0]) >= 0.9 - 1e-9
        assert parse_scene(scene_document(scene)) == scene  # the file form round-trips
