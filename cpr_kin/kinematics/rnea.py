"""Joint torques by the recursive Newton-Euler algorithm, compiled, for many states in one call.

Pinocchio's ``rnea`` (Featherstone's algorithm, in each joint's frame, motions and forces as
``[linear, angular]``) written over the arrays of a
:class:`~cpr_kin.bounds.batch_kinematics.KinematicChain` and of its bodies' inertias
(:class:`BodyArrays`): the same arithmetic, the same result to rounding, without a Python call
per state. A state's joint placements are computed once for several *channels*, each a velocity,
an acceleration and a gravity: a path's torque terms (:meth:`cpr_kin.Dynamics.path_terms`) are
three channels of one pass, where three calls of ``rnea`` would place the joints three times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays
from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]
BodiesArrays = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""A :class:`BodyArrays`' arrays, as compiled code takes them: mass, centre, inertia, armature."""


@dataclass(frozen=True)
class BodyArrays:
    """The bodies a Pinocchio model's joints carry, as arrays for compiled code.

    Body ``k`` is the one joint ``k + 1`` of the model carries (the world's is not stored), every
    link fixed to that joint merged into it, as Pinocchio's ``model.inertias`` holds them.

    Attributes:
        mass_kg: ``(J,)`` masses [kg].
        centre_m: ``(J, 3)`` centres of mass in the joint's frame [m].
        inertia_kg_m2: ``(J, 3, 3)`` rotational inertias about the centre of mass, in the joint's
            axes [kg m^2].
        armature: ``(J,)`` each joint's armature (its rotor's inertia seen at the joint) [kg m^2
            or kg], added to its torque times its acceleration as Pinocchio's ``rnea`` adds it.
    """

    mass_kg: FloatArray
    centre_m: FloatArray
    inertia_kg_m2: FloatArray
    armature: FloatArray

    @classmethod
    def from_model(cls, model: Any) -> BodyArrays:
        """The bodies of a Pinocchio model whose joints each have one coordinate."""
        joints = range(1, model.njoints)
        inertias = [model.inertias[j] for j in joints]
        armature = np.asarray(model.armature, dtype=float)
        return cls(
            mass_kg=np.array([inertia.mass for inertia in inertias], dtype=float),
            centre_m=np.array([inertia.lever for inertia in inertias], dtype=float).reshape(-1, 3),
            inertia_kg_m2=np.array([inertia.inertia for inertia in inertias], dtype=float).reshape(-1, 3, 3),
            armature=np.array([armature[model.joints[j].idx_v] for j in joints], dtype=float),
        )

    @property
    def arrays(self) -> BodiesArrays:
        """The arrays, in field order, as :func:`channel_torques` takes them."""
        return self.mass_kg, self.centre_m, self.inertia_kg_m2, self.armature


@njit
def channel_torques(
    q: FloatArray,
    velocities: FloatArray,
    accelerations: FloatArray,
    gravities: FloatArray,
    chain: ChainArrays,
    bodies: BodiesArrays,
    out: FloatArray,
) -> None:
    """Write into ``out`` ``(C, N, nq)`` the torques of ``C`` channels at ``N`` configurations.

    Channel ``c`` at configuration ``k``: Pinocchio's ``rnea(q[k], velocities[c, k],
    accelerations[c, k])`` [N m or N] with gravity ``gravities[c]`` ``(3,)`` [m/s^2] (the
    world's linear acceleration it opposes; zeros: no gravity). ``chain``:
    :attr:`~cpr_kin.bounds.batch_kinematics.KinematicChain.arrays`; ``bodies``:
    :attr:`BodyArrays.arrays`. One function, its arrays unpacked once: helpers taking them
    cost their reference counts per joint, twice the arithmetic (``docs/tuning.md``).
    """
    parents, index_q, prismatic, axes, rotations, translations, _ = chain
    mass, centre, inertia, armature = bodies
    joints = len(parents)
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    velocity, acceleration, force = np.empty((joints, 6)), np.empty((joints, 6)), np.empty((joints, 6))
    for k in range(q.shape[0]):
        for j in range(joints):  # each joint placed in its parent once, for every channel
            value = q[k, index_q[j]]
            x, y, z = axes[j, 0], axes[j, 1], axes[j, 2]
            if prismatic[j]:
                for r in range(3):
                    p0, p1, p2 = rotations[j, r, 0], rotations[j, r, 1], rotations[j, r, 2]
                    translation[j, r] = translations[j, r] + value * (p0 * x + p1 * y + p2 * z)
                    rotation[j, r, 0], rotation[j, r, 1], rotation[j, r, 2] = p0, p1, p2
                continue
            s, v = math.sin(value), 1.0 - math.cos(value)  # Rodrigues: I + sin K + (1 - cos) K^2
            m00, m01, m02 = 1.0 - v * (y * y + z * z), v * x * y - s * z, v * x * z + s * y
            m10, m11, m12 = v * x * y + s * z, 1.0 - v * (x * x + z * z), v * y * z - s * x
            m20, m21, m22 = v * x * z - s * y, v * y * z + s * x, 1.0 - v * (x * x + y * y)
            for r in range(3):
                translation[j, r] = translations[j, r]
                p0, p1, p2 = rotations[j, r, 0], rotations[j, r, 1], rotations[j, r, 2]
                rotation[j, r, 0] = p0 * m00 + p1 * m10 + p2 * m20
                rotation[j, r, 1] = p0 * m01 + p1 * m11 + p2 * m21
                rotation[j, r, 2] = p0 * m02 + p1 * m12 + p2 * m22
        for c in range(gravities.shape[0]):
            for j in range(joints):  # forward: the body's velocity and acceleration in its frame
                parent = parents[j]
                if parent < 0:
                    l0, l1, l2, w0, w1, w2 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
                    b0, b1, b2 = -gravities[c, 0], -gravities[c, 1], -gravities[c, 2]
                    u0, u1, u2 = 0.0, 0.0, 0.0
                else:
                    l0, l1, l2 = velocity[parent, 0], velocity[parent, 1], velocity[parent, 2]
                    w0, w1, w2 = velocity[parent, 3], velocity[parent, 4], velocity[parent, 5]
                    b0, b1, b2 = acceleration[parent, 0], acceleration[parent, 1], acceleration[parent, 2]
                    u0, u1, u2 = acceleration[parent, 3], acceleration[parent, 4], acceleration[parent, 5]
                # the parent's motion at this joint's origin, then in its axes (liMi.actInv)
                t0, t1, t2 = translation[j, 0], translation[j, 1], translation[j, 2]
                l0, l1, l2 = l0 - (t1 * w2 - t2 * w1), l1 - (t2 * w0 - t0 * w2), l2 - (t0 * w1 - t1 * w0)
                b0, b1, b2 = b0 - (t1 * u2 - t2 * u1), b1 - (t2 * u0 - t0 * u2), b2 - (t0 * u1 - t1 * u0)
                for r in range(3):
                    r0, r1, r2 = rotation[j, 0, r], rotation[j, 1, r], rotation[j, 2, r]
                    velocity[j, r] = r0 * l0 + r1 * l1 + r2 * l2
                    velocity[j, 3 + r] = r0 * w0 + r1 * w1 + r2 * w2
                    acceleration[j, r] = r0 * b0 + r1 * b1 + r2 * b2
                    acceleration[j, 3 + r] = r0 * u0 + r1 * u1 + r2 * u2
                # the joint's own motion S qd, S qdd and its bias v x S qd
                speed, push = velocities[c, k, index_q[j]], accelerations[c, k, index_q[j]]
                x, y, z = axes[j, 0], axes[j, 1], axes[j, 2]
                s0, s1, s2 = x * speed, y * speed, z * speed
                l0, l1, l2 = velocity[j, 0], velocity[j, 1], velocity[j, 2]
                w0, w1, w2 = velocity[j, 3], velocity[j, 4], velocity[j, 5]
                if prismatic[j]:  # S qd = (s, 0): v x S qd = (w x s, 0)
                    acceleration[j, 0] += x * push + w1 * s2 - w2 * s1
                    acceleration[j, 1] += y * push + w2 * s0 - w0 * s2
                    acceleration[j, 2] += z * push + w0 * s1 - w1 * s0
                    l0, l1, l2 = l0 + s0, l1 + s1, l2 + s2
                    velocity[j, 0], velocity[j, 1], velocity[j, 2] = l0, l1, l2
                else:  # S qd = (0, s): v x S qd = (l x s, w x s)
                    acceleration[j, 0] += l1 * s2 - l2 * s1
                    acceleration[j, 1] += l2 * s0 - l0 * s2
                    acceleration[j, 2] += l0 * s1 - l1 * s0
                    acceleration[j, 3] += x * push + w1 * s2 - w2 * s1
                    acceleration[j, 4] += y * push + w2 * s0 - w0 * s2
                    acceleration[j, 5] += z * push + w0 * s1 - w1 * s0
                    w0, w1, w2 = w0 + s0, w1 + s1, w2 + s2
                    velocity[j, 3], velocity[j, 4], velocity[j, 5] = w0, w1, w2
                # the force I a + v x* I v, I the body's spatial inertia (its mass, centre and inertia)
                body = (mass[j], centre[j, 0], centre[j, 1], centre[j, 2])
                rotational = (
                    (inertia[j, 0, 0], inertia[j, 0, 1], inertia[j, 0, 2]),
                    (inertia[j, 1, 0], inertia[j, 1, 1], inertia[j, 1, 2]),
                    (inertia[j, 2, 0], inertia[j, 2, 1], inertia[j, 2, 2]),
                )
                h0, h1, h2, k0, k1, k2 = _inertia_times(body, rotational, l0, l1, l2, w0, w1, w2)
                b0, b1, b2 = acceleration[j, 0], acceleration[j, 1], acceleration[j, 2]
                u0, u1, u2 = acceleration[j, 3], acceleration[j, 4], acceleration[j, 5]
                f0, f1, f2, e0, e1, e2 = _inertia_times(body, rotational, b0, b1, b2, u0, u1, u2)
                # v x* (h, k) = (w x h, w x k + l x h)
                force[j, 0] = f0 + w1 * h2 - w2 * h1
                force[j, 1] = f1 + w2 * h0 - w0 * h2
                force[j, 2] = f2 + w0 * h1 - w1 * h0
                force[j, 3] = e0 + w1 * k2 - w2 * k1 + l1 * h2 - l2 * h1
                force[j, 4] = e1 + w2 * k0 - w0 * k2 + l2 * h0 - l0 * h2
                force[j, 5] = e2 + w0 * k1 - w1 * k0 + l0 * h1 - l1 * h0
            for j in range(joints - 1, -1, -1):  # backward: children before parents (topological order)
                i = index_q[j]
                o = 0 if prismatic[j] else 3
                torque = (
                    axes[j, 0] * force[j, o] + axes[j, 1] * force[j, o + 1] + axes[j, 2] * force[j, o + 2]
                )
                out[c, k, i] = torque + armature[j] * accelerations[c, k, i]
                parent = parents[j]
                if parent < 0:
                    continue
                # the force at the parent's origin, in its axes (liMi.act)
                f0, f1, f2 = force[j, 0], force[j, 1], force[j, 2]
                e0, e1, e2 = force[j, 3], force[j, 4], force[j, 5]
                t0, t1, t2 = translation[j, 0], translation[j, 1], translation[j, 2]
                n0 = rotation[j, 0, 0] * f0 + rotation[j, 0, 1] * f1 + rotation[j, 0, 2] * f2
                n1 = rotation[j, 1, 0] * f0 + rotation[j, 1, 1] * f1 + rotation[j, 1, 2] * f2
                n2 = rotation[j, 2, 0] * f0 + rotation[j, 2, 1] * f1 + rotation[j, 2, 2] * f2
                force[parent, 0] += n0
                force[parent, 1] += n1
                force[parent, 2] += n2
                u0 = rotation[j, 0, 0] * e0 + rotation[j, 0, 1] * e1 + rotation[j, 0, 2] * e2
                u1 = rotation[j, 1, 0] * e0 + rotation[j, 1, 1] * e1 + rotation[j, 1, 2] * e2
                u2 = rotation[j, 2, 0] * e0 + rotation[j, 2, 1] * e1 + rotation[j, 2, 2] * e2
                force[parent, 3] += u0 + t1 * n2 - t2 * n1
                force[parent, 4] += u1 + t2 * n0 - t0 * n2
                force[parent, 5] += u2 + t0 * n1 - t1 * n0


@njit_inline
def _inertia_times(
    body: tuple[float, float, float, float],
    rotational: tuple[tuple[float, float, float], tuple[float, float, float], tuple[float, float, float]],
    l0: float,
    l1: float,
    l2: float,
    w0: float,
    w1: float,
    w2: float,
) -> tuple[float, float, float, float, float, float]:
    """A body's spatial inertia times a motion ``(l, w)``: the force ``(m (l - c x w), I_c w + c x that)``.

    ``body``: its mass [kg] and centre of mass ``c`` [m]; ``rotational``: ``I_c``, its rows
    [kg m^2] (Pinocchio's ``Inertia * Motion``). Scalars only, so that inlined it costs nothing.
    """
    m, c0, c1, c2 = body
    (i00, i01, i02), (i10, i11, i12), (i20, i21, i22) = rotational
    f0, f1, f2 = (
        m * (l0 - (c1 * w2 - c2 * w1)),
        m * (l1 - (c2 * w0 - c0 * w2)),
        m * (l2 - (c0 * w1 - c1 * w0)),
    )
    e0 = i00 * w0 + i01 * w1 + i02 * w2 + c1 * f2 - c2 * f1
    e1 = i10 * w0 + i11 * w1 + i12 * w2 + c2 * f0 - c0 * f2
    e2 = i20 * w0 + i21 * w1 + i22 * w2 + c0 * f1 - c1 * f0
    return f0, f1, f2, e0, e1, e2
