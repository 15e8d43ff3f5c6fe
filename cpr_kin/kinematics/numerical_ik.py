"""Inverse kinematics of any robot: damped least squares on Pinocchio's Jacobians, verified by FK.

:func:`solve_ik` puts the tool frame at a position, or at a pose (position and orientation),
within a tolerance. From the seed configuration first, then from seeded random ones
(``restarts``), it iterates ``dq = J^T (J J^T + lambda^2 I)^-1 e`` on the frame's error ``e``
(the position difference; for a pose, also the rotation's logarithm, in the world-aligned
frame), each step at most ``max_step`` [rad or m] per joint and clipped into the joint
ranges. From the seed, and from every other random start, the step is the least in time, not
in the joints' units (the Jacobian's columns scaled by the joints' speed limits,
:attr:`~cpr_kin.model.limits.JointLimits.speed_scales`), and those random starts are drawn
near the seed in time (each joint's draw pulled towards the seed's value by its speed scale):
where the arm can reach the target by its fast joints, a slow one (a torso lift) keeps about
its seed's value; where the seed's least-in-time descent misses the target, the seed's plain
descent is tried too (what came first before). The other random starts explore the whole
ranges with the plain step (a revolute range of more than a turn: the turn about the seed,
:func:`about_seed`). On an arm whose joints are equally fast both kinds are the same.
Every solution is checked by
forward kinematics against the target and its
tolerance; of those that pass, the ones the ``accept`` test allows (collision-free, say) come
first, and of those the ones the ``prefer`` test also passes (on a constraint, say) before
the rest, then the one the robot reaches soonest from the seed, nearest in robot motion
(``sum_j R_j |dq_j|``) of those about as soon (:func:`soonest`). A revolute joint
whose range spans more than a turn (a UR's ``[-2 pi, 2 pi]``) reaches the same pose a turn
apart: each solution is first turned by whole turns towards the seed, within the range, or a
restart's shoulder a turn away made the robot swing round for nothing. A target that
no start reaches is an :class:`~cpr_kin.common.errors.IkMissError` naming the closest the solver
came.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.certified.motion import path_weights
from cpr_kin.common.errors import CprKinError, IkMissError
from cpr_kin.kinematics.forward import frame_levers
from cpr_kin.kinematics.ik_descent import descend
from cpr_kin.kinematics.ik_target import IkTarget
from cpr_kin.kinematics.tool_chain import ToolChain
from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]
Descent = Callable[[FloatArray], tuple[FloatArray, int]]
"""A start's descent: from the start, the configuration it ends at and its steps (:func:`descent`)."""


PROGRESS = 0.05
"""The relative decrease of a start's least error that counts as progress (:attr:`IkSettings.patience`)."""
SAME_TIME_SHARE = 0.05
"""Solutions reached this share later than the soonest count as soon (:func:`soonest`): of them the
nearest in robot motion is chosen."""


@dataclass(frozen=True)
class IkSettings:
    """How :func:`solve_ik` searches.

    Attributes:
        restarts: random starts after the seed.
        iterations: steps per start.
        damping: ``lambda`` of the damped least squares [m or rad].
        max_step: largest change of a joint per step [rad or m].
        seed: seed of the random starts.
        choices: solutions found (that ``accept`` allows) before the nearest is chosen.
        patience: steps in a row that leave a start's least error (:meth:`IkTarget.excess`)
            not :data:`PROGRESS` smaller that end that start: it is stuck (at a joint limit,
            or circling), and a converging start steps far faster (``docs/tuning.md``).
        more_restarts: random starts after those when none of them found a solution that
            ``accept`` allows: near the edge of the workspace some branches of an arm's
            solutions fall short of a pose, and every start may have descended into those
            (``docs/tuning.md``).
    """

    restarts: int = 30
    iterations: int = 150
    damping: float = 1e-3
    max_step: float = 0.3
    seed: int = 0
    choices: int = 4
    patience: int = 20
    more_restarts: int = 70

    def __post_init__(self) -> None:
        counts = (("restarts", 0), ("iterations", 1), ("choices", 1), ("patience", 1), ("more_restarts", 0))
        for name, low in counts:
            value = getattr(self, name)
            if not isinstance(value, int) or isinstance(value, bool) or not low <= value <= 100_000:
                raise CprKinError(f"IkSettings.{name} = {value!r} must be an integer in [{low}, 100000]")
        for name in ("damping", "max_step"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and 0 < value <= 10):
                raise CprKinError(f"IkSettings.{name} = {value!r} must be a number in (0, 10]")


def descent(
    robot: Robot,
    target: IkTarget,
    free: NDArray[np.bool_],
    settings: IkSettings,
    scales: FloatArray | None = None,
) -> Descent:
    """One start's damped least-squares descent of ``target``, moving the ``free`` ``(nq,)`` joints.

    The returned function takes the start ``(nq,)`` [rad, m] and returns the configuration it
    ends at and the steps it took: it ends where the target is reached, after
    ``settings.iterations`` steps, or once ``settings.patience`` steps in a row have not made
    progress. It runs compiled (:mod:`cpr_kin.kinematics.ik_descent`). ``scales`` ``(nq,)``
    weigh the joints' share of each step (the robot's
    :attr:`~cpr_kin.model.limits.JointLimits.speed_scales`: the step least in time); ``None``:
    the plain least-squares step, in the joints' own units.
    """
    chain, tool = ToolChain.of(robot).arrays
    pose = target.rotation is not None
    goal = (
        np.array(target.position, dtype=float),
        np.array(target.rotation if pose else np.eye(3), dtype=float),
        np.array([target.tolerance_m, target.tolerance_rad]),
        pose,
    )
    lower, upper = np.array(robot.limits.lower, dtype=float), np.array(robot.limits.upper, dtype=float)
    rates = np.array([settings.damping, settings.max_step, PROGRESS])
    joint_scales = np.ones(robot.nq) if scales is None else np.asarray(scales, dtype=float)
    step = (np.where(np.asarray(free, dtype=bool), joint_scales, 0.0), lower, upper, rates)
    counts = (int(settings.iterations), int(settings.patience))
    return lambda q: descend(np.array(q, dtype=float), chain, tool, goal, step, counts)


def tool_reach_m(robot: Robot) -> float:
    """An upper bound of the tool frame's distance from the model's origin, in any configuration [m].

    The offsets along the chain from the origin to the tool frame, added up (a joint turns an
    offset, never lengthens it), plus each prismatic joint's largest travel
    (:func:`~cpr_kin.kinematics.forward.frame_levers`).
    """
    return frame_levers(robot, robot.tcp_frame).reach_m


def solve_ik(
    robot: Robot,
    target: IkTarget,
    seed_q: ArrayLike | None = None,
    accept: Callable[[FloatArray], bool] | None = None,
    settings: IkSettings | None = None,
    held: Sequence[str] = (),
    prefer: Callable[[FloatArray], bool] | None = None,
) -> FloatArray:
    """A configuration that puts the robot's tool frame at ``target`` (module docstring).

    Args:
        robot: the robot.
        target: the position or pose, with its tolerance.
        seed_q: the configuration to start from and stay near; default: mid-range.
        accept: a test an acceptable solution passes (e.g. clear of obstacles).
        settings: the search's parameters.
        held: joints kept at their ``seed_q`` values (the joints a ``tcp`` goal holds).
        prefer: a test of the acceptable solutions: those that pass it come first, in the
            same search (the nearest acceptable one where none does). Asked only of
            acceptable solutions.

    Raises:
        IkMissError: the target lies beyond :func:`tool_reach_m`, or no start reaches it
            within its tolerance.
        JointLimitError: ``held`` names a joint the robot does not plan.
    """
    settings = settings or IkSettings()
    missed = f"no configuration puts frame '{robot.tcp_frame}' at {np.round(target.position, 4).tolist()} m"
    distance, reach = float(np.linalg.norm(target.position)), tool_reach_m(robot)
    if distance > reach + target.tolerance_m:  # no start can reach it: say so at once
        raise IkMissError(
            f"{missed}: it lies {distance:.4g} m from the robot's base, "
            f"beyond the {reach:.4g} m its links reach"
        )
    lower, upper = robot.limits.lower, robot.limits.upper
    seed = (lower + upper) / 2 if seed_q is None else np.clip(np.asarray(seed_q, dtype=float), lower, upper)
    free = np.ones(robot.nq, dtype=bool)
    free[[robot.limits.index(name) for name in held]] = False
    revolute = np.array([unit == "rad" for unit in robot.joint_units])
    rng = np.random.default_rng(settings.seed)
    found: list[FloatArray] = []
    accepted: list[FloatArray] = []  # ``accept`` asked once per solution
    preferred: list[FloatArray] = []  # ``prefer`` asked once per accepted solution
    closest: pin.SE3 | None = None
    frame = robot.frame_id(robot.tcp_frame)
    low, high = about_seed(seed, lower, upper, revolute)
    draws = [seed, *rng.uniform(low, high, (settings.restarts, robot.nq))]
    speeds = robot.limits.speed_scales
    soon_from, anywhere_from = (
        descent(robot, target, free, settings, speeds),
        descent(robot, target, free, settings),
    )

    def reached(q: FloatArray) -> bool:
        """Whether ``q`` puts the tool frame at the target, by forward kinematics; the closest kept."""
        nonlocal closest
        pin.framesForwardKinematics(robot.model, robot.data, q)
        placement = pin.SE3(robot.data.oMf[frame])
        if closest is None or target.excess(placement) < target.excess(closest):
            closest = placement
        return bool(target.reached(placement))

    tried = 0
    while tried < len(draws):
        soon = tried % 2 == 0  # the seed and every other draw: near the seed in time
        start = seed + speeds * (draws[tried] - seed) if soon else draws[tried]
        start = np.where(free, start, seed)
        q = turned_towards((soon_from if soon else anywhere_from)(start)[0], seed, revolute, lower, upper)
        solved = reached(q)
        if not solved and tried == 0 and robot.limits.speeds_differ:  # the seed's plain descent too
            q = turned_towards(anywhere_from(start)[0], seed, revolute, lower, upper)
            solved = reached(q)
        tried += 1
        if solved:
            found.append(q)
            if accept is None or accept(q):
                accepted.append(q)
                if prefer is None or prefer(q):
                    preferred.append(q)
                    if len(preferred) >= settings.choices:
                        break
        if tried == settings.restarts + 1 and not preferred:  # then more, drawn only now
            draws += list(rng.uniform(low, high, (settings.more_restarts, robot.nq)))
    if not found:
        assert closest is not None  # the seed is always tried
        raise IkMissError(f"{missed}: the closest of {tried} IK starts came {target.miss(closest)}")
    return soonest(robot, preferred or accepted or found, seed)


def soonest(robot: Robot, solutions: Sequence[FloatArray], seed: FloatArray) -> FloatArray:
    """Of ``solutions`` (joint vectors [rad, m]), the one the robot reaches soonest from ``seed``.

    Reached soonest: the robot's :meth:`~cpr_kin.model.limits.JointLimits.move_time_s` from
    ``seed`` at most :data:`SAME_TIME_SHARE` above the least; of those, the nearest in robot
    motion (``sum_j R_j |dq_j|``, :func:`~cpr_kin.certified.motion.path_weights`), which sweeps
    the least space.
    """
    times_s = robot.limits.move_time_s(np.array(solutions) - seed)
    latest_s = (1.0 + SAME_TIME_SHARE) * times_s.min()
    soon = [q for q, time_s in zip(solutions, times_s, strict=True) if time_s <= latest_s]
    weights = path_weights(robot)
    return min(soon, key=lambda q: float(weights @ np.abs(q - seed)))


def about_seed(
    seed: FloatArray, lower: FloatArray, upper: FloatArray, revolute: NDArray[np.bool_]
) -> tuple[FloatArray, FloatArray]:
    """The box random starts are drawn from [rad, m]: the ranges, a wide revolute one's a turn about ``seed``.

    A revolute joint whose range spans more than a turn reaches every pose within any one turn
    of it, and a solution is turned towards the seed anyway (:func:`turned_towards`): its draws
    within the turn of its range nearest centred on the seed keep the starts as near the seed,
    and as spread over the turn, as a joint of one turn's. Near a limit the turn is shifted
    into the range, never cut: a seed at the limit still has the whole turn drawn.
    """
    wide = revolute & (upper - lower > 2.0 * math.pi)
    low = np.where(wide, np.clip(seed - math.pi, lower, upper - 2.0 * math.pi), lower)
    return low, np.where(wide, low + 2.0 * math.pi, upper)


def turned_towards(
    q: FloatArray, seed: FloatArray, revolute: NDArray[np.bool_], lower: FloatArray, upper: FloatArray
) -> FloatArray:
    """``q`` [rad, m], each ``revolute`` joint turned by whole turns towards ``seed`` within its range.

    The turns (2 pi each) that bring it nearest ``seed``, where that stays within ``[lower,
    upper]``; elsewhere it is kept. The same pose (module docstring).
    """
    turned = q + 2.0 * math.pi * np.round((seed - q) / (2.0 * math.pi))
    return np.asarray(np.where(revolute & (turned >= lower) & (turned <= upper), turned, q))
