"""The joint torques a trajectory asks of the robot, checked against its effort limits.

:func:`scene_dynamics` builds the robot's dynamics with the scene's payload once per
problem; :func:`held` is the one rule of a configuration the motors can hold still (gravity's
torques within every effort limit), by which :func:`check_held` refuses a start or goal.
Where gravity alone may exceed a limit between them (a heavy arm, weak shoulder motors, a
payload), :func:`gravity_limit` holds the search to it (:class:`GravityLimit`): no timing
makes a motion through a configuration the motors cannot hold feasible. :func:`torque_profile`
samples a trajectory's torques by Pinocchio's RNEA every :data:`CHECK_STEP_S` and at its
knots: the verification (:func:`torque_problems`), the report and the plots read it. It
shares nothing with the timing's torque terms (:mod:`planning.curves.torque_limits`) but the
robot model: RNEA of the trajectory's own position, velocity and acceleration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.arrays import distinct_sorted
from cpr_kin.model.robot import joint_units
from planning.curves.phase_plane import (
    kept_derivatives,
    kept_samples,
    path_acceleration,
    phase_plane_profile,
)
from planning.curves.torque_limits import UNBOUND_SHARE, profile_torques
from planning.curves.trajectory import Trajectory
from planning.errors import PayloadTooHeavyError, PlanningError
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]

LINE_SAMPLES = 64
"""Samples of the straight path on which :func:`search_torque` looks whether the torques bind."""
CHECK_STEP_S = 1e-3
"""Spacing of the instants at which a trajectory's torques are checked [s]."""
TORQUE_TOLERANCE = 1e-9
"""Relative excess of an effort limit that still passes (rounding)."""
GRAVITY_SAMPLES = 256
"""Seeded configurations of the moving joints at which :func:`gravity_limit` asks whether gravity binds."""
GRAVITY_GATE = 0.75
"""The share of an effort limit that gravity must need at one of those configurations for
:func:`gravity_limit` to hold the search to :class:`GravityLimit` (a margin for the
configurations between the samples: gravity's torques vary smoothly over the ranges)."""


def held(dynamics: ck.Dynamics, q: FloatArray) -> NDArray[np.bool_]:
    """``(N,)`` whether the motors can hold each configuration of ``q`` ``(N, nq)`` still.

    Gravity's torque at every joint within its effort limit (times ``torque_scale``).
    """
    if not len(q):
        return np.zeros(0, dtype=bool)
    return np.asarray(np.all(np.abs(dynamics.torques(q)) <= dynamics.effort, axis=1))


@dataclass(frozen=True)
class GravityLimit:
    """The configurations the motors can hold still: gravity's torques within the effort limits.

    Attributes:
        dynamics: the robot's dynamics with the scene's payload.
    """

    dynamics: ck.Dynamics

    def usage(self, q: FloatArray) -> FloatArray:
        """``(N,)`` the largest ``|gravity torque| / effort`` of the joints at ``q`` ``(N, nq)``."""
        if not len(q):
            return np.zeros(0)
        return np.asarray(self.dynamics.utilisation(self.dynamics.torques(q)).max(axis=1))

    def path_excess(self, samples: FloatArray) -> FloatArray:
        """``(S,)`` how far gravity's largest torque over its effort exceeds 1 on paths ``(S, K, nq)``.

        0 where every configuration checked can be held still. Checked at every 4th sample
        and the last: gravity's torques vary smoothly along a path.
        """
        count, k, nq = samples.shape
        checked = distinct_sorted(np.arange(0, k, 4), k - 1)
        usage = self.usage(samples[:, checked].reshape(-1, nq)).reshape(count, len(checked))
        return np.asarray(np.maximum(usage.max(axis=1) - 1.0, 0.0))

    def holds(self, q: FloatArray) -> NDArray[np.bool_]:
        """``(N,)`` whether the motors can hold each of ``q`` ``(N, nq)`` still (:func:`held`)."""
        return held(self.dynamics, q)


def gravity_limit(
    robot: ck.Robot, dynamics: ck.Dynamics, q_start: FloatArray, moving: NDArray[np.intp]
) -> GravityLimit | None:
    """The :class:`GravityLimit` of ``dynamics`` where gravity may bind, else ``None``.

    Bind: at one of :data:`GRAVITY_SAMPLES` seeded configurations (the ``moving`` joints drawn
    over their ranges, the others where they start), gravity needs :data:`GRAVITY_GATE` of an
    effort limit or more. Elsewhere (the example arms, the CPR, without a heavy payload) the
    search is spared the torques of its samples; the verification checks the torques of
    every trajectory all the same.
    """
    if not dynamics.limited:
        return None
    lower, upper = robot.limits.lower[moving], robot.limits.upper[moving]
    q = np.tile(q_start, (GRAVITY_SAMPLES, 1))
    q[:, moving] = np.random.default_rng(0).uniform(lower, upper, (GRAVITY_SAMPLES, len(moving)))
    limit = GravityLimit(dynamics)
    return limit if float(limit.usage(q).max()) >= GRAVITY_GATE else None


@dataclass(frozen=True)
class TorqueProfile:
    """A trajectory's joint torques at its check instants.

    Attributes:
        times_s: ``(T,)`` instants [s].
        torques: ``(T, nq)`` joint torques [N m or N].
        effort: ``(nq,)`` the limits they are held to [N m or N], ``inf`` where unknown.
        joint_names: the joints, in order.
    """

    times_s: FloatArray
    torques: FloatArray
    effort: FloatArray
    joint_names: tuple[str, ...]

    @property
    def utilisation(self) -> FloatArray:
        """``(T, nq)`` ``|torque| / effort`` (0 where the effort is unknown)."""
        return np.abs(self.torques) / self.effort

    @property
    def peak_utilisation(self) -> FloatArray:
        """``(nq,)`` the largest ``|torque| / effort`` of each joint."""
        return np.asarray(self.utilisation.max(axis=0))


def torque_profile(
    dynamics: ck.Dynamics, trajectory: Trajectory, step_s: float = CHECK_STEP_S
) -> TorqueProfile:
    """The torques of ``trajectory`` every ``step_s`` [s] and at its knots, by RNEA."""
    start, end = float(trajectory.knots[0]), float(trajectory.knots[-1])
    count = max(2, int(np.floor((end - start) / step_s + 1e-9)) + 1)
    times = distinct_sorted(start + step_s * np.arange(count), trajectory.knots)
    torques = dynamics.torques(trajectory(times), trajectory(times, 1), trajectory(times, 2))
    return TorqueProfile(times, torques, dynamics.effort, dynamics.joint_names)


def torque_problems(dynamics: ck.Dynamics, profile: TorqueProfile) -> list[str]:
    """The worst joint torque of a trajectory's ``profile`` beyond its effort limit, as a problem, if any."""
    usage = profile.utilisation
    if usage.max() <= 1.0 + TORQUE_TOLERANCE:
        return []
    k, j = (int(index) for index in np.unravel_index(int(np.argmax(usage)), usage.shape))
    name = dynamics.joint_names[j]
    return [
        f"drives the torque of joint '{name}' to {usage[k, j]:.3f} x its effort limit "
        f"({abs(profile.torques[k, j]):.4g} of {dynamics.effort[j]:.4g}{_unit(dynamics, j)}) at t = "
        f"{profile.times_s[k]:.3f} s"
    ]


def scene_dynamics(robot: ck.Robot, scene: Scene) -> ck.Dynamics:
    """The robot's dynamics with the scene's payload and ``torque_scale``.

    Raises:
        PlanningError: the payload's frame is not the robot's.
    """
    try:
        return ck.robot_dynamics(robot, scene.payload, scene.torque_scale)
    except ck.CprKinError as exc:
        raise PlanningError(f"payload: {exc}") from None


def check_held(dynamics: ck.Dynamics, scene: Scene, label: str, q: FloatArray) -> None:
    """Refuse the scene's start or goal (``label``) at ``q`` if the motors cannot hold it still.

    Raises:
        PayloadTooHeavyError: gravity's torque at ``q`` exceeds a joint's effort limit (times
            ``torque_scale``), naming the joint, the torque and the limit.
    """
    if held(dynamics, np.atleast_2d(q))[0]:
        return
    holding = np.abs(dynamics.torques(q)[0])
    j = int(np.argmax(holding / dynamics.effort))
    unit = _unit(dynamics, j)
    carried = "" if scene.payload is None else f" with the {scene.payload.mass_kg:g} kg payload"
    fix = (
        f"lighten the payload or choose another {label}"
        if scene.payload is not None
        else f"choose another {label}, or give the URDF the effort limits the arm has (a "
        "counterbalanced arm's springs are not in its URDF)"
    )
    raise PayloadTooHeavyError(
        f"holding the {label} still{carried} takes {holding[j]:.4g}{unit} at joint "
        f"'{dynamics.joint_names[j]}', beyond its effort limit {dynamics.effort[j]:.4g}{unit} "
        f"(URDF effort x torque_scale {dynamics.torque_scale:g}); {fix}"
    )


def search_torque(
    robot: ck.Robot, dynamics: ck.Dynamics, q_start: FloatArray, q_goal: FloatArray
) -> ck.Dynamics | None:
    """``dynamics`` if the torques bind on the straight path from start to goal, else ``None``.

    Bind: the fastest profile of that path under the velocity and acceleration limits
    (:data:`LINE_SAMPLES` samples) asks some joint for :data:`~planning.curves.torque_limits.UNBOUND_SHARE`
    of its effort or more. Then the search's duration estimate keeps the torques (more work
    per candidate; on MotionBenchMaker's Panda problems at 3 kg, paths up to 26 % faster);
    otherwise the timing alone holds them, as it always does.
    """
    if not dynamics.limited or np.allclose(q_start, q_goal):
        return None
    limits = robot.limits
    points = np.linspace(q_start, q_goal, LINE_SAMPLES)
    # writable copies of the (read-only) limits, as the search's own are: the kernels below are
    # then loaded once in a process, not once more for read-only arguments
    velocity, acceleration = np.array(limits.velocity), np.array(limits.acceleration)
    index = kept_samples(points, velocity)
    steps, d1, d2 = kept_derivatives(points, index, velocity)
    x = phase_plane_profile(d1, d2, steps, velocity, acceleration, np.zeros_like(d1))
    terms = dynamics.path_terms(points[index], d1, d2)
    usage = dynamics.utilisation(profile_torques(terms, x, path_acceleration(x, steps)))
    return dynamics if usage.max() >= UNBOUND_SHARE else None


def _unit(dynamics: ck.Dynamics, joint: int) -> str:
    """`` N m`` for a revolute joint's torque, `` N`` for a prismatic joint's force."""
    return " N" if joint_units(dynamics.model)[joint] == "m" else " N m"
