"""Joint placements of many configurations at once, compiled.

Pinocchio computes forward kinematics one configuration per call, with about a microsecond
of Python overhead each. For a pre-check of thousands of configurations
(:mod:`cpr_kin.bounds.pair_bounds`) the chain is copied into plain arrays (:class:`KinematicChain`)
that compiled code walks per configuration (:func:`place_joints`), then places the capsules
fixed to the joints (:func:`place_capsule`). Joints must have one
degree of freedom (revolute or prismatic, about any fixed axis), as every CPR joint does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.reach import joint_axis
from cpr_kin.common.compiled import njit, njit_inline
from cpr_kin.common.errors import CprKinError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
ChainArrays = tuple[IntArray, IntArray, BoolArray, FloatArray, FloatArray, FloatArray, BoolArray]
"""A :class:`KinematicChain`'s arrays, in its field order, as compiled code takes them."""


@njit_inline
def place_joints(
    q: FloatArray,
    chain: ChainArrays,
    rotation_out: FloatArray,
    translation_out: FloatArray,
    local: FloatArray,
) -> None:
    """Write every joint's ``joint_in_world`` at one configuration ``q`` ``(nq,)``.

    ``chain`` is :attr:`KinematicChain.arrays`; ``rotation_out`` ``(J, 3, 3)``
    and ``translation_out`` ``(J, 3)`` receive the placements, in joint order. ``local`` is
    a ``(4, 3)`` work array (allocating per call would cost more than the arithmetic).
    Written with scalars and explicit indices (array views cost reference counting), and
    skipping products with the identity where a placement has no rotation (``aligned``).
    """
    parents, index_q, prismatic, axes, rotations, translations, aligned = chain
    for j in range(len(parents)):
        value = q[index_q[j]]
        x, y, z = axes[j, 0], axes[j, 1], axes[j, 2]
        # rows 0-2 of ``local``: the rotation of the joint's placement in its parent composed
        # with its motion (unless it is the identity); row 3: the translation
        turns = not prismatic[j]
        if prismatic[j]:
            for r in range(3):
                if aligned[j]:
                    local[3, r] = translations[j, r] + value * axes[j, r]
                else:
                    p0, p1, p2 = rotations[j, r, 0], rotations[j, r, 1], rotations[j, r, 2]
                    local[3, r] = translations[j, r] + value * (p0 * x + p1 * y + p2 * z)
                    local[r, 0], local[r, 1], local[r, 2] = p0, p1, p2
        else:  # Rodrigues: I + sin K + (1 - cos) K^2, K the axis' cross-product matrix
            s, v = np.sin(value), 1.0 - np.cos(value)
            m00, m01, m02 = 1.0 - v * (y * y + z * z), v * x * y - s * z, v * x * z + s * y
            m10, m11, m12 = v * x * y + s * z, 1.0 - v * (x * x + z * z), v * y * z - s * x
            m20, m21, m22 = v * x * z - s * y, v * y * z + s * x, 1.0 - v * (x * x + y * y)
            if aligned[j]:
                local[0, 0], local[0, 1], local[0, 2] = m00, m01, m02
                local[1, 0], local[1, 1], local[1, 2] = m10, m11, m12
                local[2, 0], local[2, 1], local[2, 2] = m20, m21, m22
            for r in range(3):
                local[3, r] = translations[j, r]
                if not aligned[j]:
                    p0, p1, p2 = rotations[j, r, 0], rotations[j, r, 1], rotations[j, r, 2]
                    local[r, 0] = p0 * m00 + p1 * m10 + p2 * m20
                    local[r, 1] = p0 * m01 + p1 * m11 + p2 * m21
                    local[r, 2] = p0 * m02 + p1 * m12 + p2 * m22
        identity = aligned[j] and not turns  # the local rotation is the identity
        parent = parents[j]
        for r in range(3):
            if parent < 0:
                translation_out[j, r] = local[3, r]
                for c in range(3):
                    rotation_out[j, r, c] = (1.0 if r == c else 0.0) if identity else local[r, c]
            else:
                a0, a1, a2 = (
                    rotation_out[parent, r, 0],
                    rotation_out[parent, r, 1],
                    rotation_out[parent, r, 2],
                )
                translation_out[j, r] = (
                    translation_out[parent, r] + a0 * local[3, 0] + a1 * local[3, 1] + a2 * local[3, 2]
                )
                if identity:
                    rotation_out[j, r, 0], rotation_out[j, r, 1], rotation_out[j, r, 2] = a0, a1, a2
                else:
                    for c in range(3):
                        rotation_out[j, r, c] = a0 * local[0, c] + a1 * local[1, c] + a2 * local[2, c]


@njit_inline
def place_capsule(
    c: int,
    rotation: FloatArray,
    translation: FloatArray,
    capsule_joint: IntArray,
    capsule_ends: FloatArray,
    world: FloatArray,
) -> None:
    """Write capsule ``c``'s segment in the world frame into ``world[c]`` ``(2, 3)`` [m].

    The capsule is fixed to joint ``capsule_joint[c]`` (``-1``: to the world), its end points
    ``capsule_ends[c]`` in that joint's frame; ``rotation`` and ``translation`` are the joints'
    placements (:func:`place_joints`). Every compiled bound places its capsules here.
    """
    j = capsule_joint[c]
    for e in range(2):
        for r in range(3):
            if j < 0:
                world[c, e, r] = capsule_ends[c, e, r]
            else:
                world[c, e, r] = (
                    translation[j, r]
                    + rotation[j, r, 0] * capsule_ends[c, e, 0]
                    + rotation[j, r, 1] * capsule_ends[c, e, 1]
                    + rotation[j, r, 2] * capsule_ends[c, e, 2]
                )


@njit_inline
def place_capsules(
    q: FloatArray,
    chain: ChainArrays,
    capsule_joint: IntArray,
    capsule_ends: FloatArray,
    rotation: FloatArray,
    translation: FloatArray,
    local: FloatArray,
    world: FloatArray,
) -> None:
    """Write every capsule's segment in the world frame at one configuration ``q`` ``(nq,)`` into ``world``.

    :func:`place_joints` (into ``rotation``, ``translation``, with ``local`` its work array),
    then :func:`place_capsule` of each capsule: what a bound of every capsule does first.
    """
    place_joints(q, chain, rotation, translation, local)
    for c in range(len(capsule_joint)):
        place_capsule(c, rotation, translation, capsule_joint, capsule_ends, world)


@dataclass(frozen=True)
class KinematicChain:
    """A Pinocchio model's joints as arrays, for compiled code.

    Joint ``k`` here is Pinocchio's joint ``k + 1`` (the world is not stored).

    Attributes:
        parents: ``(J,)`` parent joint (``-1``: the world).
        index_q: ``(J,)`` index of the joint's coordinate in ``q``.
        prismatic: ``(J,)`` prismatic (else revolute).
        axes: ``(J, 3)`` unit axis in the joint's frame.
        rotations: ``(J, 3, 3)`` rotation of the joint's placement in its parent.
        translations: ``(J, 3)`` translation of that placement [m].
        aligned: ``(J,)`` that rotation is the identity (the joint's frame is its parent's).
    """

    parents: IntArray
    index_q: IntArray
    prismatic: NDArray[np.bool_]
    axes: FloatArray
    rotations: FloatArray
    translations: FloatArray
    aligned: NDArray[np.bool_]

    @classmethod
    def from_model(cls, model: Any) -> KinematicChain:
        """The chain of a Pinocchio model.

        Raises:
            CprKinError: a joint has more than one degree of freedom.
        """
        joints = range(1, model.njoints)
        for j in joints:
            if model.joints[j].nq != 1 or model.joints[j].nv != 1:
                raise CprKinError(
                    f"joint '{model.names[j]}' has {model.joints[j].nq} coordinates; batch kinematics "
                    "supports one-degree-of-freedom revolute and prismatic joints only"
                )
        kinds = [joint_axis(model.joints[j]) for j in joints]
        rotations = np.array([model.jointPlacements[j].rotation for j in joints], dtype=float).reshape(
            -1, 3, 3
        )
        return cls(
            parents=np.array([model.parents[j] - 1 for j in joints], dtype=np.int64),
            index_q=np.array([model.joints[j].idx_q for j in joints], dtype=np.int64),
            prismatic=np.array([prismatic for prismatic, _ in kinds], dtype=np.bool_),
            axes=np.array([axis for _, axis in kinds], dtype=float).reshape(-1, 3),
            rotations=rotations,
            translations=np.array(
                [model.jointPlacements[j].translation for j in joints], dtype=float
            ).reshape(-1, 3),
            aligned=np.array([np.array_equal(r, np.eye(3)) for r in rotations], dtype=np.bool_),
        )

    @property
    def arrays(self) -> ChainArrays:
        """The arrays, in field order: :func:`place_joints`'s ``chain``."""
        return (
            self.parents,
            self.index_q,
            self.prismatic,
            self.axes,
            self.rotations,
            self.translations,
            self.aligned,
        )

    def placements(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Rotations ``(N, J, 3, 3)`` and translations ``(N, J, 3)`` [m] of every joint in the world.

        Args:
            q: ``(N, nq)`` configurations [rad, m] (not checked against limits).
        """
        batch = np.ascontiguousarray(q, dtype=float)
        n, joints = len(batch), len(self.parents)
        rotations, translations = np.empty((n, joints, 3, 3)), np.empty((n, joints, 3))
        _place_batch(batch, self.arrays, rotations, translations)
        return rotations, translations


@njit
def _place_batch(
    q: FloatArray, chain: ChainArrays, rotation_out: FloatArray, translation_out: FloatArray
) -> None:
    joints = len(chain[0])
    rotation, translation, local = np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3))
    for k in range(len(q)):
        place_joints(q[k], chain, rotation, translation, local)
        for j in range(joints):  # element by element: a slice assignment allocates
            for r in range(3):
                translation_out[k, j, r] = translation[j, r]
                for c in range(3):
                    rotation_out[k, j, r, c] = rotation[j, r, c]


def sampled_configurations(model: Any, count: int, rng: np.random.Generator) -> FloatArray:
    """``(count, nq)`` configurations drawn uniformly within ``model``'s position limits.

    Each range is clipped to one turn, ``[-pi, pi]`` (a continuous joint's is unbounded).
    """
    lower = np.clip(model.lowerPositionLimit, -np.pi, np.pi)
    upper = np.clip(model.upperPositionLimit, -np.pi, np.pi)
    return np.asarray(rng.uniform(lower, np.maximum(upper, lower), (count, model.nq)))
