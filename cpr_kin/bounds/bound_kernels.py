"""Compiled lower bounds of the distance between a robot capsule and an obstacle.

What :class:`cpr_kin.bounds.pair_bounds.PairBounds` runs, configuration by configuration: the
kinematic chain places every robot capsule (:func:`cpr_kin.bounds.batch_kinematics.place_joints`),
then each robot-obstacle pair is bounded from below.

Obstacle bounds, in the obstacle's frame, for the robot's segment (before subtracting the
robot capsule's radius):

- sphere (radius ``R``): the exact distance from its centre to the segment, minus ``R``;
- cylinder and capsule (axis along local z, half length ``h``, radius ``R``): with ``d`` the
  segment's distance from the z axis and ``g`` its gap to the slab ``|z| <= h``,
  ``sqrt(max(d - R, 0)^2 + g^2)`` for the cylinder and ``sqrt(d^2 + g^2) - R`` for the capsule
  (for any point of the segment, its distance from the axis is at least ``d`` and from the
  slab at least ``g``);
- box, and any other shape by its local bounding box (half sides ``h``): the exact distance
  from the segment to the box (:func:`~cpr_kin.bounds.box_distance.segment_box_distance`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, place_capsules
from cpr_kin.bounds.box_distance import excess, segment_box_distance
from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

SPHERE, CYLINDER, CAPSULE, BOX = 0, 1, 2, 3
"""Obstacle bound kinds, as the compiled code reads them."""


@njit
def _point_segment(ax: float, ay: float, az: float, dx: float, dy: float, dz: float) -> float:
    """Distance from the origin to the segment from ``a`` along ``d`` (``d`` may be zero)."""
    length2 = dx * dx + dy * dy + dz * dz
    t = 0.0
    if length2 > 0.0:
        t = min(max(-(ax * dx + ay * dy + az * dz) / length2, 0.0), 1.0)
    x, y, z = ax + t * dx, ay + t * dy, az + t * dz
    return float(np.sqrt(x * x + y * y + z * z))


@njit
def _gap(low: float, high: float, half: float) -> float:
    """Gap between the intervals ``[low, high]`` and ``[-half, half]`` (0 where they overlap)."""
    return max(low - half, -half - high, 0.0)


@njit_inline
def _to_obstacle(x: float, y: float, z: float, o: int, rotation: FloatArray) -> tuple[float, float, float]:
    """The vector ``(x, y, z)``, in the world's axes, in obstacle ``o``'s axes (``rotation[o]``'s columns)."""
    return (
        rotation[o, 0, 0] * x + rotation[o, 1, 0] * y + rotation[o, 2, 0] * z,
        rotation[o, 0, 1] * x + rotation[o, 1, 1] * y + rotation[o, 2, 1] * z,
        rotation[o, 0, 2] * x + rotation[o, 1, 2] * y + rotation[o, 2, 2] * z,
    )


@njit_inline
def _in_obstacle(
    world: FloatArray, c: int, e: int, o: int, obstacle_rotation: FloatArray, obstacle_origin: FloatArray
) -> tuple[float, float, float]:
    """End ``e`` of capsule ``c``'s segment ``world[c]`` in obstacle ``o``'s frame [m]."""
    x = world[c, e, 0] - obstacle_origin[o, 0]
    y = world[c, e, 1] - obstacle_origin[o, 1]
    z = world[c, e, 2] - obstacle_origin[o, 2]
    return _to_obstacle(x, y, z, o, obstacle_rotation)


@njit_inline
def _segment_obstacle_bound(
    world: FloatArray,
    c: int,
    o: int,
    kind: IntArray,
    obstacle_rotation: FloatArray,
    obstacle_origin: FloatArray,
    obstacle_radius: FloatArray,
    obstacle_half: FloatArray,
) -> float:
    """A lower bound [m] of the distance from capsule ``c``'s segment ``world[c]`` to obstacle ``o``.

    The module docstring's bound of obstacle ``o``'s ``kind``, the capsule's radius not yet
    subtracted. Scalars and explicit indices: an array view costs reference counting, and
    this helper is inlined into the kernels' loops over pairs.
    """
    ax, ay, az = _in_obstacle(world, c, 0, o, obstacle_rotation, obstacle_origin)
    bx, by, bz = _in_obstacle(world, c, 1, o, obstacle_rotation, obstacle_origin)
    dx, dy, dz = bx - ax, by - ay, bz - az
    radius = obstacle_radius[o]
    if kind[o] == SPHERE:
        bound = _point_segment(ax, ay, az, dx, dy, dz) - radius
    elif kind[o] == BOX:
        hx, hy, hz = obstacle_half[o, 0], obstacle_half[o, 1], obstacle_half[o, 2]
        bound = segment_box_distance(ax, ay, az, dx, dy, dz, hx, hy, hz)
    else:
        axis_distance = _point_segment(ax, ay, 0.0, dx, dy, 0.0)
        gap = _gap(min(az, bz), max(az, bz), obstacle_half[o, 2])
        if kind[o] == CYLINDER:
            radial = max(axis_distance - radius, 0.0)
            bound = np.sqrt(radial * radial + gap * gap)
        else:
            bound = np.sqrt(axis_distance * axis_distance + gap * gap) - radius
    return float(bound)


@njit
def pair_bounds(
    q: FloatArray,
    out: FloatArray,
    chain: ChainArrays,
    capsule_joint: IntArray,
    capsule_ends: FloatArray,
    capsule_radius: FloatArray,
    pair_capsule: IntArray,
    pair_obstacle: IntArray,
    kind: IntArray,
    obstacle_rotation: FloatArray,
    obstacle_origin: FloatArray,
    obstacle_radius: FloatArray,
    obstacle_half: FloatArray,
) -> None:
    """Write into ``out[n, p]`` a lower bound of pair ``p``'s distance at configuration ``q[n]`` [m].

    Pair ``p`` is capsule ``pair_capsule[p]`` (fixed to joint ``capsule_joint``, segment
    ``capsule_ends`` in that joint's frame, radius ``capsule_radius``) and obstacle
    ``pair_obstacle[p]`` (bound ``kind``, placed by ``obstacle_rotation`` and
    ``obstacle_origin``, with its radius and half sides or half length).
    """
    joints = len(chain[0])
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    world = np.empty((len(capsule_joint), 2, 3))
    scratch = np.empty((4, 3))
    for n in range(len(q)):
        place_capsules(q[n], chain, capsule_joint, capsule_ends, rotation, translation, scratch, world)
        for p in range(len(pair_capsule)):
            c, o = pair_capsule[p], pair_obstacle[p]
            bound = _segment_obstacle_bound(
                world, c, o, kind, obstacle_rotation, obstacle_origin, obstacle_radius, obstacle_half
            )
            out[n, p] = bound - capsule_radius[c]


@njit_inline
def _centre_box_gap(
    x: float, y: float, z: float, o: int, obstacle_rotation: FloatArray, obstacle_half: FloatArray
) -> float:
    """Distance [m] from the point ``(x, y, z)`` (in the world's axes, from box ``o``'s centre) to the box.

    A capsule's points lie within its reach of its centre, so this less the reach bounds the
    capsule's distance from the box from below: a cheaper test than the segment's
    (:func:`~cpr_kin.bounds.box_distance.segment_box_distance`) where a turned flat box (a
    shelf, a table top) lets many capsules into its bounding sphere (``docs/tuning.md``, Kernels).
    """
    px, py, pz = _to_obstacle(x, y, z, o, obstacle_rotation)
    half = obstacle_half
    ex, ey, ez = excess(px, half[o, 0]), excess(py, half[o, 1]), excess(pz, half[o, 2])
    return float(np.sqrt(ex * ex + ey * ey + ez * ez))


@njit
def groups_below(
    q: FloatArray,
    threshold: float,
    out: BoolArray,
    pair_group: IntArray,
    chain: ChainArrays,
    capsule_joint: IntArray,
    capsule_ends: FloatArray,
    capsule_radius: FloatArray,
    capsule_reach: FloatArray,
    pair_capsule: IntArray,
    pair_obstacle: IntArray,
    kind: IntArray,
    obstacle_rotation: FloatArray,
    obstacle_origin: FloatArray,
    obstacle_radius: FloatArray,
    obstacle_half: FloatArray,
    obstacle_reach: FloatArray,
    obstacle_extent: FloatArray,
    blocks: tuple[IntArray, FloatArray, IntArray, IntArray],
) -> None:
    """Write into ``out[n, g]`` whether a pair of group ``g`` has a bound below ``threshold`` [m] at ``q[n]``.

    The arguments are :func:`pair_bounds`', plus each pair's group (``pair_group``, ``(P,)``
    in ``[0, G)`` for ``out`` of shape ``(N, G)``), the bounding-sphere radii of the capsules
    (``capsule_reach``) and obstacles (``obstacle_reach``), the half sides of a box in the
    world's axes about each obstacle's centre that holds it (``obstacle_extent``, ``(O, 3)``)
    and the pairs in blocks (:attr:`~cpr_kin.bounds.obstacle_blocks.ObstacleBlocks.arrays`).
    A block needs no pair tested where the capsule's sphere is farther than ``threshold`` from
    its cluster's box along an axis; a pair none where the sphere is that far from the
    obstacle's box (a shelf's board or a table top is thin along one), or from the
    obstacle's sphere, or from a box obstacle itself (:func:`_centre_box_gap`); nor where its
    group is already below, and a configuration stops once every group is. Each test only
    skips pairs whose bound would be above ``threshold``: ``out`` is what the bounds alone give.
    """
    block_capsule, block_box, block_start, order = blocks
    joints = len(chain[0])
    rotation, translation = np.empty((joints, 3, 3)), np.empty((joints, 3))
    world = np.empty((len(capsule_joint), 2, 3))
    scratch = np.empty((4, 3))
    for n in range(len(q)):
        place_capsules(q[n], chain, capsule_joint, capsule_ends, rotation, translation, scratch, world)
        out[n, :] = False
        open_groups = out.shape[1]
        for b in range(len(block_capsule)):
            c = block_capsule[b]
            mx = 0.5 * (world[c, 0, 0] + world[c, 1, 0])
            my = 0.5 * (world[c, 0, 1] + world[c, 1, 1])
            mz = 0.5 * (world[c, 0, 2] + world[c, 1, 2])
            slack = threshold + capsule_reach[c]
            if (
                mx < block_box[b, 0, 0] - slack
                or mx > block_box[b, 1, 0] + slack
                or my < block_box[b, 0, 1] - slack
                or my > block_box[b, 1, 1] + slack
                or mz < block_box[b, 0, 2] - slack
                or mz > block_box[b, 1, 2] + slack
            ):
                continue
            for i in range(block_start[b], block_start[b + 1]):
                p = order[i]
                group = pair_group[p]
                if out[n, group]:
                    continue
                o = pair_obstacle[p]
                x, y, z = mx - obstacle_origin[o, 0], my - obstacle_origin[o, 1], mz - obstacle_origin[o, 2]
                if (
                    abs(x) > slack + obstacle_extent[o, 0]
                    or abs(y) > slack + obstacle_extent[o, 1]
                    or abs(z) > slack + obstacle_extent[o, 2]
                ):
                    continue
                apart = slack + obstacle_reach[o]
                if x * x + y * y + z * z > apart * apart:
                    continue
                if kind[o] == BOX and _centre_box_gap(x, y, z, o, obstacle_rotation, obstacle_half) > slack:
                    continue
                bound = _segment_obstacle_bound(
                    world, c, o, kind, obstacle_rotation, obstacle_origin, obstacle_radius, obstacle_half
                )
                if bound - capsule_radius[c] <= threshold:
                    out[n, group] = True
                    open_groups -= 1
                    if open_groups == 0:
                        break
            if open_groups == 0:
                break
