"""Link pairs a few millimetres apart by design: held to contact only.

Some URDFs give two links a joint apart shapes that stay a few millimetres from each other
wherever the joints are, a housing around the joint between them (Tiago's ``arm_5_link``
and ``arm_tool_link``, 4.3-6.6 mm; the G1's ``left_elbow_link`` and
``left_wrist_pitch_link``, 9.5 mm), or that stay that close wherever they do not meet
(example-robot-data's ``finger_edu``: its middle link 3-4 mm from the base's housing, and
into it over a seventh of the joints' box). Held to a self margin of 10 mm, such a pair
refuses every configuration, so no plan is possible. MoveIt checks a robot's own pairs with
no padding, and its setup assistant disables pairs never seen in collision outright; here
such a pair stays checked, for contact only: where it meets, the configuration is refused.

:func:`close_pairs` finds, among the checked pairs, those whose distance is below
:data:`CLOSE_LIMIT_M` at every one of :data:`SAMPLES` seeded configurations within the joint
ranges and positive at one at least, and their largest sampled distance
(:attr:`cpr_kin.Robot.close_pairs`). A :class:`cpr_kin.CollisionWorld` whose self
margin exceeds a pair's largest distance holds that pair to contact only: the pair's distance
counts the margin as kept (:attr:`cpr_kin.collision.self_collision.SelfCollision.allowance_m`).
A pair that comes apart beyond the margin somewhere is held to the margin like any other, and
one that touches in every sample is touching by design (:mod:`cpr_kin.bounds.overlapping_pairs`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import pinocchio as pin

from cpr_kin.bounds.batch_kinematics import sampled_configurations

if TYPE_CHECKING:  # a robot with exact meshes imports them
    from cpr_kin.shapes.exact_meshes import ExactMesh

SAMPLES = 1000
"""Seeded configurations in which a pair must stay close to be close by design."""
MESH_SAMPLES = 16
"""Of those, the configurations where a pair refined by exact meshes is measured on them: those
where its shapes are farthest apart (``docs/tuning.md``, Pairs close by design)."""
CLOSE_LIMIT_M = 0.05
"""Largest distance [m] a pair close by design may keep: a self margin above it excuses no
pair farther than this."""


@dataclass(frozen=True)
class ClosePair:
    """A checked pair of collision geometries a few millimetres apart by design.

    Attributes:
        geometries: the two geometries' indices in the robot's collision model.
        links: the links they hang on.
        largest_m: their largest coal distance over the samples [m], positive; a self margin
            above it holds the pair to contact only.
    """

    geometries: tuple[int, int]
    links: tuple[str, str]
    largest_m: float

    def held_to_contact(self, self_margin_m: float) -> bool:
        """Whether a self margin of ``self_margin_m`` [m] holds the pair to contact only (above its gap)."""
        return self.largest_m < self_margin_m


def close_pairs(
    model: Any,
    collision_model: Any,
    pairs: Sequence[tuple[int, int]],
    links: Sequence[str],
    samples: int = SAMPLES,
    meshes: Mapping[int, ExactMesh] | None = None,
) -> tuple[ClosePair, ...]:
    """The ``pairs`` (geometry indices) within :data:`CLOSE_LIMIT_M` at every sample, apart at one.

    ``links`` names each geometry's link, by index; ``meshes``: the robot's exact meshes by
    geometry index (:attr:`cpr_kin.Robot.exact_meshes`). The distances are coal's of the
    robot's collision shapes (a concave link's convex hull), and a pair's largest is its
    meshes' where they refine it: measured at the :data:`MESH_SAMPLES` configurations where
    its shapes are farthest apart (a mesh is no nearer than its hull, and at most the pair's
    excess farther: a hull's largest alone could hold to contact a pair whose meshes keep the
    margin, as Baxter's shoulder and elbow, 4 mm apart on their hulls).

    The configurations are drawn uniformly within ``model``'s ranges (seed 0). A pair's
    capsule bound above the limit at any of them rules it out
    (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`); coal decides the rest, configuration by
    configuration, until the pair comes apart beyond the limit.
    """
    if not pairs:
        return ()
    from cpr_kin.bounds.self_bounds import bounded_pairs  # a robot with pairs of its own only

    q = sampled_configurations(model, samples, np.random.default_rng(0))
    candidates, geometry_model = bounded_pairs(model, collision_model, pairs, q, CLOSE_LIMIT_M)
    if not candidates:
        return ()
    data, geometry_data = model.createData(), geometry_model.createData()
    shapes_m = np.full((len(q), len(candidates)), -np.inf)  # coal's distances, where computed
    alive = np.ones(len(candidates), dtype=bool)
    for n, x in enumerate(q):
        pin.updateGeometryPlacements(model, data, geometry_model, geometry_data, x)
        for k in np.flatnonzero(alive).tolist():
            shapes_m[n, k] = pin.computeDistance(geometry_model, geometry_data, k).min_distance
            alive[k] = shapes_m[n, k] < CLOSE_LIMIT_M  # where it touches, it may still be close elsewhere
        if not alive.any():
            return ()
    largest = shapes_m.max(axis=0)
    if meshes:
        from cpr_kin.shapes.exact_pairs import ExactPairs

        exact = ExactPairs(geometry_model, meshes)
        for k in np.flatnonzero(alive & exact.refined).tolist():
            for n in np.argsort(-shapes_m[:, k], kind="stable")[:MESH_SAMPLES].tolist():
                pin.updateGeometryPlacements(model, data, geometry_model, geometry_data, q[n])
                largest[k] = max(largest[k], exact.distance(geometry_data, k, float(shapes_m[n, k])))
            alive[k] = largest[k] < CLOSE_LIMIT_M
    return tuple(
        ClosePair((a, b), (links[a], links[b]), float(largest[k]))
        for k, (a, b) in enumerate(candidates)
        if alive[k] and largest[k] > 0.0
    )
