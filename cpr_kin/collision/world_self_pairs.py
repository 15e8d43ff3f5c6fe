"""The robot's own pairs as a world checks them: less a scene's allowed ones, some held to contact."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.collision.self_collision import SelfCollision
from cpr_kin.model.robot import Robot


def world_self_collision(
    robot: Robot, allowed_pairs: Sequence[tuple[str, str]], self_margin_m: float, num_threads: int
) -> SelfCollision:
    """``robot``'s checked pairs (:attr:`cpr_kin.Robot.self_pairs`) but the link pairs ``allowed_pairs``.

    A pair closer than ``self_margin_m`` [m] by design (:attr:`cpr_kin.Robot.close_pairs`) is
    held to contact only (:attr:`~cpr_kin.collision.self_collision.SelfCollision.allowance_m`); the
    robot's exact meshes decide where its hulls come within a margin.
    """
    allowed = {frozenset(pair) for pair in allowed_pairs}
    links = [g.link for g in robot.geometries]
    kept = tuple((a, b) for a, b in robot.self_pairs if frozenset((links[a], links[b])) not in allowed)
    contact_only = {c.geometries for c in robot.close_pairs if c.held_to_contact(self_margin_m)}
    screen = None
    if kept:  # the split's machinery, for a robot with pairs of its own only
        from cpr_kin.collision.self_split import robot_self_screen

        screen = robot_self_screen(robot, kept, self_margin_m)
    return SelfCollision(
        robot.model,
        robot.collision_model,
        kept,
        [g.name for g in robot.geometries],
        num_threads,
        reach=robot_reach(robot),
        allowance_m=np.array([self_margin_m if pair in contact_only else 0.0 for pair in kept]),
        screen=screen,
        exact_meshes=robot.exact_meshes,
    )
