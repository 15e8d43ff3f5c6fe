"""Each robot geometry's bounding box fixed to its joint: a second bound of a pair beside the capsules'.

A capsule bounds a long link well and a squat one poorly: about a mobile base's disc, or a
torso's broad column, it reaches half the disc's width above and below it, and an arm passing
over the base stays in doubt there, so coal is asked (``docs/tuning.md``, Kernels). The
geometry's own bounding box (in its frame, swept radius included: coal's local AABB) hugs
such a shape. Where positive, the distance from the other geometry's capsule to this box,
less that capsule's radius, is at most coal's distance between the two geometries, as the
capsules' distance is (:func:`box_capsule_bound`). A pair's bound is the largest of them
(:func:`boxed_pair_bound`), asked by the self bounds (:mod:`cpr_kin.bounds.self_bounds`,
:mod:`cpr_kin.bounds.self_blocks`) only where the capsules leave the pair in doubt.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.box_distance import segment_box_distance
from cpr_kin.bounds.obstacle_bounds import local_box
from cpr_kin.common.compiled import njit_inline

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


class JointBoxes(NamedTuple):
    """Boxes enclosing geometries, each fixed to its joint (the compiled kernels' arguments).

    Attributes:
        joint: ``(G,)`` the joint each moves with, ``-1``: fixed to the world.
        axes: ``(G, 3, 3)`` its axes (columns) in that joint's frame.
        centre: ``(G, 3)`` its centre in that joint's frame [m].
        half: ``(G, 3)`` its half sides along its axes [m].
    """

    joint: IntArray
    axes: FloatArray
    centre: FloatArray
    half: FloatArray


def joint_boxes(collision_model: Any, geometries: Sequence[int]) -> JointBoxes:
    """The bounding boxes of ``collision_model``'s ``geometries`` in their joints' frames, in order."""
    joints, axes, centres, halves = [], [], [], []
    for g in geometries:
        obj = collision_model.geometryObjects[g]
        centre, half = local_box(obj.geometry)
        rotation = np.asarray(obj.placement.rotation, dtype=float)  # geometry in its joint's frame
        joints.append(int(obj.parentJoint) - 1)  # joint -1: fixed to the world
        axes.append(rotation)
        centres.append(rotation @ centre + np.asarray(obj.placement.translation, dtype=float))
        halves.append(half)
    return JointBoxes(
        np.array(joints, dtype=np.int64),
        np.array(axes, dtype=float).reshape(-1, 3, 3),
        np.array(centres, dtype=float).reshape(-1, 3),
        np.array(halves, dtype=float).reshape(-1, 3),
    )


@njit_inline
def _in_box(
    g: int,
    rotation: FloatArray,
    translation: FloatArray,
    boxes: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    x: float,
    y: float,
    z: float,
) -> tuple[float, float, float]:
    """The world point ``(x, y, z)`` [m] in box ``g``'s frame (:func:`box_capsule_bound`)."""
    box_joint, box_axes, box_centre, _ = boxes
    j = box_joint[g]
    if j >= 0:  # into the joint's frame first
        x, y, z = x - translation[j, 0], y - translation[j, 1], z - translation[j, 2]
        x, y, z = (
            rotation[j, 0, 0] * x + rotation[j, 1, 0] * y + rotation[j, 2, 0] * z,
            rotation[j, 0, 1] * x + rotation[j, 1, 1] * y + rotation[j, 2, 1] * z,
            rotation[j, 0, 2] * x + rotation[j, 1, 2] * y + rotation[j, 2, 2] * z,
        )
    x, y, z = x - box_centre[g, 0], y - box_centre[g, 1], z - box_centre[g, 2]
    axes = box_axes[g]
    return (
        axes[0, 0] * x + axes[1, 0] * y + axes[2, 0] * z,
        axes[0, 1] * x + axes[1, 1] * y + axes[2, 1] * z,
        axes[0, 2] * x + axes[1, 2] * y + axes[2, 2] * z,
    )


@njit_inline
def box_capsule_bound(
    g: int,
    rotation: FloatArray,
    translation: FloatArray,
    boxes: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    segment: FloatArray,
    radius: float,
) -> float:
    """A lower bound [m] of the distance between geometry ``g`` and a capsule: box ``g`` to the capsule.

    ``rotation`` and ``translation`` are the joints' placements
    (:func:`~cpr_kin.bounds.batch_kinematics.place_joints`), ``boxes`` :class:`JointBoxes`'
    arrays, ``segment`` ``(2, 3)`` the capsule's segment in the world [m] and ``radius`` its
    radius [m]. The segment is brought into the box's frame and its exact distance to the box
    (:func:`~cpr_kin.bounds.box_distance.segment_box_distance`) less ``radius`` returned where
    positive; ``-inf`` where the capsule reaches the box: the box bounds how far apart two
    shapes are, not how deep they overlap (coal's negative distance), which the capsules do.
    """
    ax, ay, az = _in_box(g, rotation, translation, boxes, segment[0, 0], segment[0, 1], segment[0, 2])
    bx, by, bz = _in_box(g, rotation, translation, boxes, segment[1, 0], segment[1, 1], segment[1, 2])
    half = boxes[3][g]
    distance = segment_box_distance(ax, ay, az, bx - ax, by - ay, bz - az, half[0], half[1], half[2])
    return distance - radius if distance > radius else -np.inf


@njit_inline
def boxed_pair_bound(
    a: int,
    b: int,
    rotation: FloatArray,
    translation: FloatArray,
    boxes: tuple[IntArray, FloatArray, FloatArray, FloatArray],
    world: FloatArray,
    radius: FloatArray,
    bound: float,
    threshold: float,
) -> float:
    """Pair ``a``-``b``'s capsule ``bound`` [m] raised by each geometry's box while at most ``threshold``.

    ``world`` holds the capsules' segments in the world (``world[a]``, ``world[b]``, placed),
    ``radius`` their radii [m]; the other arguments are :func:`box_capsule_bound`'s. Box ``a``
    against capsule ``b`` first, then box ``b`` against capsule ``a``, each only while the
    bound is still within ``threshold``: the rule of every self bound that asks the boxes.
    """
    if bound <= threshold:
        bound = max(bound, box_capsule_bound(a, rotation, translation, boxes, world[b], radius[b]))
    if bound <= threshold:
        bound = max(bound, box_capsule_bound(b, rotation, translation, boxes, world[a], radius[a]))
    return bound
