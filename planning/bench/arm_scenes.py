"""Seeded random scenes for any arm: a start, a goal pose, and a ball across the way between them.

:mod:`planning.bench.scene_generator` draws the CPR's scenes from its geometry; an arm someone
brings (a URDF, an example-robot-data name) has none we know. So :func:`blocked_scene` draws
in the robot's own joint space: a start configuration and a goal configuration in the middle
60 % of every joint's range whose tool positions lie at least half the arm's reach apart,
and a ball of 12 % of that reach at the tool's position halfway along the straight joint-space
way between them, at least 10 % of the reach from the base's height on the side the arm
reaches: above the base, or below it for an arm that hangs (a flying arm under its drone,
an arm mounted upside down), one whose median tool height over the middle of its ranges
lies more than 10 % of its reach below the base (:func:`reaching_side`). The goal is given
as the tool's pose (solved by the planner's IK), the start as the configuration. Start and goal must keep
``margin_m + 0.02`` m from the ball and ``self_clearance_m`` between the robot's own checked
pairs, and gravity's torques there must be within the URDF's effort limits (the planner
refuses an end its motors cannot hold still); a draw that does not is drawn again. The
straight way is blocked; whether a way around exists is for the planners to find out.
The scene keeps the default self margin, or half ``self_clearance_m`` where that is below the
default; its ends lie outside the margin the planner asks of them, checked as the plan checks
them (a pair of links close by design that ``self_clearance_m`` lets touch may be held to that
margin).
"""

from __future__ import annotations

from collections import Counter
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import PlanningError
from planning.pipeline.scene import DEFAULT_SELF_MARGIN_M, MAX_SAFETY_MARGIN_M
from planning.pipeline.settings import MAX_SEED
from planning.pipeline.torques import held
from planning.validation import integer_in, number_in

DRAWS = 4000
"""Most draws of a start and goal before :func:`blocked_scene` gives up."""
MIDDLE_SHARE = 0.6
"""The share of each joint's range, about its middle, that configurations are drawn from."""
SIDE_DRAWS = 256
"""Configurations whose tool heights tell on which side of its base an arm reaches (:func:`reaching_side`)."""
BASE_LEVEL_SHARE = 0.1
"""How far from the base's height the ball's centre lies at least, and how far below it an arm's
median tool height must lie for it to hang, as a share of the arm's reach."""


def reaching_side(robot: ck.Robot, reach_m: float) -> int:
    """``1`` where ``robot`` reaches up from its base, ``-1`` where it hangs below it.

    It hangs where the median tool height [m] of :data:`SIDE_DRAWS` configurations drawn in the
    middle :data:`MIDDLE_SHARE` of its ranges (a fixed seed: the scenes' own draws are untouched) lies more
    than :data:`BASE_LEVEL_SHARE` of its reach ``reach_m`` [m] below the base; a UR arm,
    which reaches about as far below its base as above it, reaches up.
    """
    draws = _middle_draws(robot, np.random.default_rng(0), SIDE_DRAWS)
    height_m = float(np.median(ck.frame_poses(robot, draws)[:, 2, 3]))
    return -1 if height_m < -BASE_LEVEL_SHARE * reach_m else 1


def _middle_draws(robot: ck.Robot, rng: np.random.Generator, count: int) -> NDArray[np.float64]:
    """``(count, nq)`` configurations drawn uniformly in the middle :data:`MIDDLE_SHARE` of every range."""
    lower, upper = robot.limits.lower, robot.limits.upper
    middle, half = (lower + upper) / 2, (upper - lower) / 2
    return rng.uniform(middle - MIDDLE_SHARE * half, middle + MIDDLE_SHARE * half, (count, robot.nq))


def blocked_scene(
    name: str,
    robot_entry: str | dict[str, Any],
    robot: ck.Robot,
    seed: int,
    margin_m: float = 0.02,
    self_clearance_m: float = 0.02,
    draws: int = DRAWS,
) -> dict[str, Any]:
    """A scene file's document (module docstring) for ``robot``, drawn from ``seed``.

    Args:
        name: the scene's name.
        robot_entry: what the scene file's ``robot:`` holds (a name, a URDF path, a mapping).
        robot: that robot, loaded.
        seed: seed of every draw.
        margin_m: the scene's safety margin [m].
        self_clearance_m: the least distance between the robot's own pairs at start and goal [m].
        draws: most draws of a start and goal.

    Raises:
        PlanningError: no start and goal of ``draws`` draws qualify (the message counts why), or
            ``draws`` is no whole number >= 1, ``seed`` no non-negative integer, ``margin_m``
            or ``self_clearance_m`` not a margin the scene file allows.
    """
    if not (isinstance(draws, int) and draws >= 1):
        raise PlanningError(f"draws = {draws!r} must be a whole number >= 1")
    integer_in("seed", seed, 0, MAX_SEED)
    number_in("margin_m", margin_m, 0.0, MAX_SAFETY_MARGIN_M, unit="m")
    number_in("self_clearance_m", self_clearance_m, 0.0, MAX_SAFETY_MARGIN_M, unit="m", low_open=True)
    rng = np.random.default_rng(seed)
    middle = (robot.limits.lower + robot.limits.upper) / 2
    reach = float(np.linalg.norm(ck.frame_poses(robot, middle[None])[0][:3, 3]))
    side = reaching_side(robot, reach)
    dynamics = ck.robot_dynamics(robot)
    self_margin_m = (
        self_clearance_m / 2 if self_clearance_m < DEFAULT_SELF_MARGIN_M else DEFAULT_SELF_MARGIN_M
    )
    # the ends checked as the plan checks them too: a pair close by design that a world of
    # ``self_clearance_m`` lets touch may be held to the scene's lower margin
    planned = ck.CollisionWorld(robot, [], self_margin_m=self_margin_m).self_collision
    too_close: Counter[tuple[str, str]] = Counter()  # the closest pair of each end refused for it
    refused: Counter[str] = Counter()  # why each draw was refused (REFUSALS' keys)
    for _ in range(draws):
        start, goal = _middle_draws(robot, rng, 2)
        tools = ck.frame_poses(robot, np.array([start, (start + goal) / 2, goal]))
        if np.linalg.norm(tools[0, :3, 3] - tools[2, :3, 3]) < 0.5 * reach:
            refused["near"] += 1
            continue
        if side * tools[1, 2, 3] < BASE_LEVEL_SHARE * reach:
            refused["low"] += 1
            continue
        ball = ck.Obstacle.sphere(0.12 * reach, tuple(tools[1, :3, 3]), name="ball")
        world = ck.CollisionWorld(robot, [ball], self_margin_m=self_clearance_m)
        ends = np.array([start, goal])
        if world.clearance_batch(ends).clearance_m.min() <= margin_m + 0.02:
            refused["ball"] += 1
            continue
        if world.self_collision:
            distance, pair = world.self_collision.distances(ends)
            if distance.min() <= self_clearance_m or (
                planned and planned.violated(ends, self_margin_m).any()
            ):
                too_close[world.self_collision.pairs[int(pair[np.argmin(distance)])]] += 1
                refused["self"] += 1
                continue
        if not held(dynamics, ends).all():
            refused["gravity"] += 1
            continue
        return {
            "name": name,
            "robot": robot_entry,
            "safety_margin": margin_m,
            **({"self_margin": self_margin_m} if self_margin_m != DEFAULT_SELF_MARGIN_M else {}),
            "start": {"q": start.tolist()},
            "goal": {"pose": {"xyz": tools[2, :3, 3].tolist(), "rpy": _rpy(tools[2, :3, :3])}},
            "obstacles": [
                {"name": "ball", "shape": "sphere", "radius": 0.12 * reach, "xyz": list(map(float, ball.xyz))}
            ],
            "planner": {"seed": seed},
        }
    counts = ", ".join(f"{count} {REFUSALS[why]}" for why, count in refused.most_common())
    blocker = [why for why in REFUSALS if refused[why]][-1]  # the last test refused every draw it saw
    fix = _fix(blocker, robot, too_close)
    raise PlanningError(
        f"no start and goal of {draws} draws for '{name}' keep {margin_m + 0.02:g} m from the ball and "
        f"{self_clearance_m:g} m between the robot's own pairs, with gravity's torques within the effort "
        f"limits (refused: {counts}); {fix}"
    )


REFUSALS = {
    "near": "with the tool's ends less than half the reach apart",
    "low": "with the tool's midway point less than a tenth of the reach from the base's height",
    "ball": "with an end near the ball",
    "self": "with the robot's own pairs too close",
    "gravity": "where the motors cannot hold an end against gravity",
}
"""Why a draw of :func:`blocked_scene` is refused, in the order of its tests; its error counts them."""


def _fix(blocker: str, robot: ck.Robot, too_close: Counter[tuple[str, str]]) -> str:
    """What to do about ``blocker`` (a :data:`REFUSALS` key), the test no draw passed."""
    if blocker == "self":
        unlisted = "" if robot.srdf_path is not None else ", or give the robot its SRDF (none was found)"
        (a, b), count = too_close.most_common(1)[0]
        return (
            f"lower self_clearance_m{unlisted} ({count} of the {sum(too_close.values())} draws refused "
            f"for their own pairs had {a} and {b} closest: if they sit that close by design, allow "
            "the pair in the SRDF)"
        )
    if blocker == "low":
        return (
            "the generator puts the ball a tenth of the reach above the base of an arm that reaches up, "
            "below the base of one that hangs; an arm that moves about its base's height (in its "
            "horizontal plane) has no such scene: write its scenes by hand"
        )
    if blocker == "ball":
        return "its links stay near the ball whatever its ends: lower margin_m, or write its scenes by hand"
    if blocker == "gravity":
        return "check the URDF's masses and effort limits, or give the scenes a lighter arm"
    return "its reach and joint ranges leave no room for the ball between its ends: write its scenes by hand"


def _rpy(rotation: np.ndarray) -> list[float]:
    """Roll, pitch, yaw [rad] of a rotation matrix."""
    import pinocchio as pin

    return [float(v) for v in pin.rpy.matrixToRpy(rotation)]
