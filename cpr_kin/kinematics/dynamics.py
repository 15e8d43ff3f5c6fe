"""A robot's rigid-body dynamics with a payload: joint torques by Pinocchio's RNEA, effort limits.

:func:`robot_dynamics` copies a robot's Pinocchio model, adds the payload's inertia to the
body that carries its frame (the tool frame unless the payload names another), and keeps
the URDF's effort limits times a safety factor. Torques are the recursive Newton-Euler
algorithm (Pinocchio's ``rnea``, compiled for many states at once: :mod:`cpr_kin.kinematics.rnea`):
gravity, Coriolis and inertia, the payload included, for the planned joints (the held ones are
rigid, their links part of the bodies that carry them).

A link the URDF gives no ``<inertial>`` is massless, as the URDF specification and
Pinocchio take it; :attr:`Dynamics.massless_links` names those that have a collision or
visual shape (a body the URDF forgot to weigh), so a report can say so. An effort limit of
0 or none in the URDF means unknown: that joint's torque is not limited.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, KinematicChain
from cpr_kin.common.errors import CprKinError
from cpr_kin.common.names import unprintable
from cpr_kin.kinematics.rnea import BodiesArrays, BodyArrays, channel_torques
from cpr_kin.shapes.obstacles import Obstacle

if TYPE_CHECKING:
    from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]

MAX_PAYLOAD_KG = 1000.0
"""Heaviest payload accepted [kg]: more than any serial arm's rated payload."""
MAX_COM_OFFSET_M = 5.0
"""Farthest a payload's centre of mass may lie from its frame [m]."""
PAYLOAD_NAME = "payload"
"""What a payload is called unless it is given a name (its collision geometry's name)."""
TORQUE_SCALE_RANGE = (1e-3, 1.0)
"""Allowed safety factors on the effort limits: the torque may use this share of them."""


@dataclass(frozen=True)
class Payload:
    """A rigid load carried by the robot: an attached object, with its mass and its shape.

    Attributes:
        mass_kg: its mass [kg], in ``[0, MAX_PAYLOAD_KG]``.
        com_in_frame_m: its centre of mass in ``frame`` [m].
        inertia_kg_m2: its ``(3, 3)`` rotational inertia about the centre of mass, in the
            frame's axes [kg m^2]; ``None``: a point mass.
        frame: the frame it is attached to; ``None``: the robot's tool frame.
        shape: its collision shape, placed in the frame (an :class:`~cpr_kin.Obstacle`'s
            box, sphere, cylinder, capsule or mesh, a mesh by its convex hull; its name
            unused); ``None``: none, only its mass counts (:func:`cpr_kin.kinematics.carried.carrying`
            attaches it to the robot).
        touch_links: links of the robot the shape may touch (the fingers that hold it): no
            self-clearance is required between them, as MoveIt's ``touch_links``.
        name: what messages and reports call it (MoveIt's object id).
        touch_obstacles: obstacles the shape may touch (the table it is set down on): no
            clearance is required between them, as MoveIt's allowed contacts between an
            attached object and a world object.
    """

    mass_kg: float
    com_in_frame_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    inertia_kg_m2: tuple[tuple[float, float, float], ...] | None = None
    frame: str | None = None
    shape: Obstacle | None = None
    touch_links: tuple[str, ...] = ()
    name: str = PAYLOAD_NAME
    touch_obstacles: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        mass = self.mass_kg
        if not isinstance(mass, int | float) or not 0.0 <= float(mass) <= MAX_PAYLOAD_KG:
            raise CprKinError(
                f"payload mass_kg = {mass!r} is outside [0, {MAX_PAYLOAD_KG:g}] kg; give the load's mass [kg]"
            )
        com = np.asarray(self.com_in_frame_m, dtype=float)
        if com.shape != (3,) or not np.all(np.isfinite(com)) or np.linalg.norm(com) > MAX_COM_OFFSET_M:
            raise CprKinError(
                f"payload com = {np.asarray(self.com_in_frame_m).tolist()} must be 3 finite coordinates [m] "
                f"within {MAX_COM_OFFSET_M:g} m of its frame"
            )
        object.__setattr__(self, "com_in_frame_m", tuple(float(c) for c in com))
        for key in ("touch_links", "touch_obstacles"):
            names = getattr(self, key)
            if isinstance(names, str) or not all(isinstance(n, str) for n in names):
                raise CprKinError(f"payload {key} = {names!r} must be a sequence of names")
            object.__setattr__(self, key, tuple(names))
        if not isinstance(self.name, str) or not self.name or unprintable(self.name) is not None:
            raise CprKinError(f"payload name = {self.name!r} must be printable text")
        if self.inertia_kg_m2 is not None:
            inertia = _checked_inertia(self.inertia_kg_m2)
            object.__setattr__(self, "inertia_kg_m2", tuple(tuple(float(v) for v in row) for row in inertia))

    def frame_on(self, robot: Robot) -> str:
        """The frame that holds the payload on ``robot``: its :attr:`frame`, else the robot's tool frame."""
        return self.frame or robot.tcp_frame

    def inertia(self) -> Any:
        """The payload as a ``pinocchio.Inertia`` in its frame."""
        rotational = np.zeros((3, 3)) if self.inertia_kg_m2 is None else np.array(self.inertia_kg_m2)
        return pin.Inertia(float(self.mass_kg), np.array(self.com_in_frame_m), rotational)


def _checked_inertia(values: ArrayLike) -> FloatArray:
    """A physical rotational inertia: symmetric, positive semi-definite, triangle inequality."""
    try:
        inertia = np.array(values, dtype=float)
    except (TypeError, ValueError):
        inertia = np.full(1, np.nan)
    if inertia.shape == (3,):
        inertia = np.diag(inertia)
    if inertia.shape != (3, 3) or not np.all(np.isfinite(inertia)):
        raise CprKinError(
            f"payload inertia = {np.asarray(values, dtype=object).tolist()} must be [Ixx, Iyy, Izz] or a "
            "3 x 3 matrix [kg m^2]"
        )
    principal = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
    scale = max(float(np.abs(inertia).max()), 1e-12)
    physical = (
        np.allclose(inertia, inertia.T, atol=1e-9 * scale)
        and principal.min() >= -1e-9 * scale
        and principal[2] <= principal[0] + principal[1] + 1e-9 * scale
    )
    if not physical:
        raise CprKinError(
            f"payload inertia {inertia.tolist()} kg m^2 is not a rigid body's: it must be symmetric with "
            f"principal moments {principal.round(6).tolist()} >= 0 and each at most the sum of the others"
        )
    return inertia


@dataclass(frozen=True, eq=False)
class Dynamics:
    """The robot's joint torques with its payload, and their limits.

    Build it with :func:`robot_dynamics`.

    Attributes:
        joint_names: the planned joints, in configuration order.
        model: Pinocchio model with the payload's inertia added.
        effort: the effort limits times ``torque_scale`` [N m or N], ``inf`` where unknown.
        payload: the payload, if any.
        torque_scale: share of the URDF's effort limits the torques may use.
        massless_links: links with a shape but no ``<inertial>`` (module docstring).
    """

    joint_names: tuple[str, ...]
    model: Any = field(repr=False)
    effort: FloatArray
    payload: Payload | None = None
    torque_scale: float = 1.0
    massless_links: tuple[str, ...] = ()
    _arrays: tuple[ChainArrays, BodiesArrays, FloatArray] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.effort.setflags(write=False)
        gravity = np.array(self.model.gravity.linear, dtype=float)
        chain = KinematicChain.from_model(self.model).arrays
        object.__setattr__(self, "_arrays", (chain, BodyArrays.from_model(self.model).arrays, gravity))

    @property
    def limited(self) -> bool:
        """Some joint has a known effort limit."""
        return bool(np.isfinite(self.effort).any())

    def torques(self, q: ArrayLike, qd: ArrayLike | None = None, qdd: ArrayLike | None = None) -> FloatArray:
        """``(T, nq)`` joint torques [N m or N] at ``(T, nq)`` positions, velocities and accelerations.

        ``qd`` and ``qdd`` default to zero: the torques that hold the robot still (gravity).
        Pinocchio's ``rnea`` at each state, in one compiled call for all ``T``.

        Raises:
            CprKinError: states not ``(T, nq)`` alike.
        """
        q = np.atleast_2d(np.asarray(q, dtype=float))
        qd, qdd = (np.zeros_like(q) if d is None else d for d in (qd, qdd))
        q, qd, qdd = self._states(q, qd, qdd)
        return np.asarray(self._channels(q, qd[None], qdd[None], with_gravity=(True,))[0])

    def path_terms(
        self, q: FloatArray, dq: FloatArray, ddq: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The torques along a path ``q(s)`` as ``slope s'' + curve s'^2 + offset``, each ``(T, nq)``.

        With ``qd = dq s'`` and ``qdd = dq s'' + ddq s'^2``, RNEA is affine in ``s''`` and
        ``s'^2``: ``slope = M(q) dq``, ``curve = M(q) ddq + C(q, dq) dq`` and ``offset = g(q)``
        (Pham and Pham 2018, TOPP-RA's torque constraint): three channels of one pass, the two
        first without gravity.

        Raises:
            CprKinError: states not ``(T, nq)`` alike.
        """
        q, dq, ddq = self._states(q, dq, ddq)
        still = np.zeros_like(q)
        offset, slope, curve = self._channels(
            q, np.stack([still, still, dq]), np.stack([still, dq, ddq]), with_gravity=(True, False, False)
        )
        return slope, curve, offset

    def _states(self, *arrays: ArrayLike) -> tuple[FloatArray, ...]:
        """``arrays`` as ``(T, nq)`` C-ordered floats of one shape: the compiled loop reads them unchecked.

        Raises:
            CprKinError: one is not ``(T, nq)``, or not the first one's shape.
        """
        states = tuple(np.ascontiguousarray(np.atleast_2d(np.asarray(a, dtype=float))) for a in arrays)
        shape = states[0].shape
        if len(shape) != 2 or shape[1] != self.model.nq or any(a.shape != shape for a in states):
            raise CprKinError(
                f"torques need positions, velocities and accelerations of one shape (T, {self.model.nq}), "
                f"a row per state; got {', '.join(str(a.shape) for a in states)}"
            )
        return states

    def _channels(
        self, q: FloatArray, velocities: FloatArray, accelerations: FloatArray, with_gravity: tuple[bool, ...]
    ) -> FloatArray:
        """``(C, T, nq)`` :func:`~cpr_kin.kinematics.rnea.channel_torques` at ``q`` (:meth:`_states`)."""
        chain, bodies, gravity = self._arrays
        gravities = np.array([gravity if on else np.zeros(3) for on in with_gravity])
        out = np.empty(velocities.shape)
        channel_torques(q, velocities, accelerations, gravities, chain, bodies, out)
        return out

    def utilisation(self, torques: FloatArray) -> FloatArray:
        """``|torque| / effort`` per sample and joint (0 where the effort is unknown)."""
        return np.abs(torques) / self.effort


def robot_dynamics(robot: Robot, payload: Payload | None = None, torque_scale: float = 1.0) -> Dynamics:
    """The robot's :class:`Dynamics` carrying ``payload``, its efforts times ``torque_scale``.

    Raises:
        CprKinError: an unknown payload frame, or ``torque_scale`` outside :data:`TORQUE_SCALE_RANGE`.
    """
    low, high = TORQUE_SCALE_RANGE
    if not isinstance(torque_scale, int | float) or not low <= float(torque_scale) <= high:
        raise CprKinError(
            f"torque_scale = {torque_scale!r} is outside [{low:g}, {high:g}]: the share of the URDF's "
            "effort limits the torques may use"
        )
    model = robot.model.copy()
    if payload is not None and payload.mass_kg > 0.0:
        frame = model.frames[robot.frame_id(payload.frame_on(robot))]
        model.inertias[frame.parentJoint] += frame.placement.act(payload.inertia())
    effort = np.array(model.effortLimit, dtype=float) * float(torque_scale)
    effort[~(effort > 0.0)] = np.inf
    return Dynamics(
        joint_names=robot.joint_names,
        model=model,
        effort=effort,
        payload=payload,
        torque_scale=float(torque_scale),
        massless_links=robot.massless_links,
    )
