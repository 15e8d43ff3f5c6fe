from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.narrow_passages import (
    ARM_ABOVE_AXIS_M,
    KINDS,
    PLAY_RANGE_M,
    TIGHT_PLAY_RANGE_M,
    TOOL_BELOW_AXIS_M,
    narrow_scene,
)
from planning.bench.scene_generator import generate_scenes
from planning.errors import PlanningError
from planning.io.scene_file import parse_scene, scene_document


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


def test_narrow_passages_are_reproducible_and_block_the_straight_swing(robot: ck.Robot) -> None:
    scenes = generate_scenes(12, seed=3, robot=robot, narrow=9)
    assert generate_scenes(12, seed=3, robot=robot, narrow=9) == scenes
    # the regular scenes do not depend on how many narrow ones follow
    assert scenes[:3] == generate_scenes(3, seed=3, robot=robot)
    narrow = scenes[3:]
    assert [s.name for s in narrow] == [
        f"{kind}_{i:03d}" for i, kind in zip(range(3, 12), KINDS * 3, strict=True)
    ]
    blocked = 0
    for scene in narrow:
        names = {o.name for o in scene.obstacles}
        assert names in (
            {"crate", "beam"},
            {"wall_below", "wall_above", "wall_beside"},
            {"pillar_0", "pillar_1"},
        )
        world = ck.CollisionWorld(robot, scene.obstacles)
        q = np.array([scene.start.configuration(robot), scene.goal.configuration(robot)])
        assert world.clearance_batch(q).min_clearance_m.min() >= scene.safety_margin + 0.02 - 1e-9
        line = q[0] + np.linspace(0.0, 1.0, 200)[:, None] * (q[1] - q[0])
        blocked += bool(world.margin_violated(line, scene.safety_margin).any())
        assert parse_scene(scene_document(scene)) == scene
    # a narrow passage stands in the way of the straight joint-space swing (pillars flank the
    # goal: the straight swing may pass them)
    assert blocked >= 6


def test_narrow_count_is_checked(robot: ck.Robot) -> None:
    with pytest.raises(PlanningError, match=r"seed = -1 must be an integer in \[0, "):
        generate_scenes(2, -1, robot)  # numpy's own error before: "expected non-negative integer"
    with pytest.raises(PlanningError, match=r"count = -2 must be an integer in \[0, 100000\]"):
        generate_scenes(-2, 0, robot)
    with pytest.raises(PlanningError, match="narrow = 5"):
        generate_scenes(3, robot=robot, narrow=5)
    with pytest.raises(PlanningError, match="kind = 'tunnel'"):
        narrow_scene(np.random.default_rng(0), robot, "tunnel")  # type: ignore[arg-type]
    with pytest.raises(PlanningError, match=r"kinds = \['tunnel'\]; allowed: one or more of beam"):
        generate_scenes(3, robot=robot, narrow=1, kinds=["tunnel"])  # type: ignore[list-item]


def test_slots_are_millimetres_wide_and_overhangs_cover_the_goal(robot: ck.Robot) -> None:
    scenes = generate_scenes(8, seed=4, robot=robot, narrow=8, kinds=["slot", "overhang"])
    assert [s.name for s in scenes] == [f"{('slot', 'overhang')[i % 2]}_{i:03d}" for i in range(8)]
    for scene in scenes:
        margin = scene.safety_margin
        obstacles = {o.name: o for o in scene.obstacles}
        q = np.array([scene.start.configuration(robot), scene.goal.configuration(robot)])
        world = ck.CollisionWorld(robot, scene.obstacles)
        assert world.clearance_batch(q).min_clearance_m.min() >= margin + 0.02 - 1e-9
        if scene.name.startswith("slot"):
            crate, beam = obstacles["crate"], obstacles["beam"]
            assert crate.size is not None and beam.size is not None
            gap = (beam.xyz[2] - beam.size[2] / 2) - crate.size[2]
            play = gap - (ARM_ABOVE_AXIS_M + TOOL_BELOW_AXIS_M + 2 * margin)
            assert TIGHT_PLAY_RANGE_M[0] <= play <= TIGHT_PLAY_RANGE_M[1]  # 1-5 mm a side
        else:
            board = obstacles["board"]
            assert board.size is not None and set(obstacles) == {"board", "post"}
            underside = board.xyz[2] - board.size[2] / 2
            arm_top = 0.25 + q[1, 1] + ARM_ABOVE_AXIS_M  # z_c = 0.25 + d2, and half the arm beam
            play = underside - arm_top - margin
            assert PLAY_RANGE_M[0] <= play <= PLAY_RANGE_M[1]
            raised = q[1].copy()
            raised[1] += play + 0.01  # the goal's arm lifted into the margin under the board
            assert world.margin_violated(raised[None], margin)[0]
