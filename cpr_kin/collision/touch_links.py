"""Which robot-obstacle pairs a world checks: every one but an obstacle's ``touch_links``.

An obstacle may name links of the robot that may touch it (:attr:`cpr_kin.Obstacle.touch_links`:
the fingers at a part they grasp or have just let go, MoveIt's allowed contacts between a link
and a world object). Their pairs with it are left out of every query, as a robot's allowed
self pairs are. What the robot carries (:func:`cpr_kin.carrying`) is checked against every
obstacle whatever the link that holds it.
"""

from __future__ import annotations

from collections.abc import Sequence

import pinocchio as pin

from cpr_kin.common.errors import CprKinError
from cpr_kin.model.robot import Robot
from cpr_kin.shapes.obstacles import Obstacle


def checked_pairs(robot: Robot, obstacles: Sequence[Obstacle]) -> list[tuple[int, int]]:
    """``(robot geometry index, obstacle index)`` of every pair a world checks, geometry by geometry.

    Raises:
        CprKinError: an obstacle's ``touch_links`` names a link the robot does not have (a
            typo would leave the pair checked, silently).
    """
    links = {f.name for f in robot.model.frames if f.type == pin.FrameType.BODY}
    for obstacle in obstacles:
        unknown = sorted(set(obstacle.touch_links) - links)
        if unknown:
            raise CprKinError(
                f"obstacle '{obstacle.name}' touch_links {unknown} are not links of the robot; its links "
                f"with shapes: {sorted({g.link for g in robot.geometries if not g.carried})}"
            )
    return [
        (geometry.index, k)
        for geometry in robot.geometries
        for k, obstacle in enumerate(obstacles)
        if geometry.carried or geometry.link not in obstacle.touch_links
    ]
