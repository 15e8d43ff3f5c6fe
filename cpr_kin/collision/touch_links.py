"""Which robot-obstacle pairs a world checks: every one but those allowed to touch.

An obstacle may name links of the robot that may touch it (:attr:`cpr_kin.Obstacle.touch_links`:
the fingers at a part they grasp or have just let go, MoveIt's allowed contacts between a link
and a world object), and what the robot carries the obstacles it may touch
(:attr:`cpr_kin.Payload.touch_obstacles`: the table a part is set down on, MoveIt's allowed
contacts between an attached object and a world object). Their pairs are left out of every
query, as a robot's allowed self pairs are. A carried object is not one of the links that hold
it: an obstacle's ``touch_links`` leave it checked.
"""

from __future__ import annotations

from collections.abc import Sequence

from cpr_kin.common.errors import CprKinError
from cpr_kin.model.robot import Robot
from cpr_kin.shapes.obstacles import Obstacle


def checked_pairs(robot: Robot, obstacles: Sequence[Obstacle]) -> list[tuple[int, int]]:
    """``(robot geometry index, obstacle index)`` of every pair a world checks, geometry by geometry.

    Raises:
        CprKinError: an obstacle's ``touch_links`` names a link the robot does not have, or a
            carried object's ``touch_obstacles`` an obstacle that is not there (a typo would
            leave the pair checked, silently).
    """
    for obstacle in obstacles:
        robot.check_links(obstacle.touch_links, f"obstacle '{obstacle.name}' touch_links")
    names = {o.name for o in obstacles}
    for geometry in robot.geometries:
        unknown = sorted(set(geometry.touches) - names)
        if unknown:
            raise CprKinError(
                f"payload '{geometry.name}' touch_obstacles {unknown} are not obstacles here; the "
                f"obstacles: {sorted(names)}"
            )
    return [
        (geometry.index, k)
        for geometry in robot.geometries
        for k, obstacle in enumerate(obstacles)
        if obstacle.name not in geometry.touches
        and (geometry.carried or geometry.link not in obstacle.touch_links)
    ]
