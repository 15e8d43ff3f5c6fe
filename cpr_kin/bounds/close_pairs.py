"""Link pairs a few millimetres apart by design, never touching: held to contact only.

Some URDFs give two links a joint apart shapes that stay a few millimetres from each other
wherever the joints are, a housing around the joint between them (Tiago's ``arm_5_link``
and ``arm_tool_link``, 4.3-6.6 mm; the G1's ``left_elbow_link`` and
``left_wrist_pitch_link``, 9.5 mm). Held to a self margin of 10 mm, such a pair refuses
every configuration, so no plan is possible. MoveIt checks a robot's own pairs with no
padding, and its setup assistant disables pairs never seen in collision outright; here such
a pair stays checked, for contact only.

:func:`close_pairs` finds, among the checked pairs, those whose coal distance is positive and
below :data:`CLOSE_LIMIT_M` at every one of :data:`SAMPLES` seeded configurations within the
joint ranges, and their largest sampled distance (:attr:`cpr_kin.Robot.close_pairs`). A
:class:`cpr_kin.CollisionWorld` whose self margin exceeds a pair's largest distance holds
that pair to contact only: the pair's distance counts the margin as kept
(:attr:`cpr_kin.collision.self_collision.SelfCollision.allowance_m`). A pair that touches anywhere in
the samples, or comes apart beyond the margin, is held to the margin like any other.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from cpr_kin.bounds.batch_kinematics import sampled_configurations

SAMPLES = 1000
"""Seeded configurations in which a pair must stay close, and apart, to be close by design."""
CLOSE_LIMIT_M = 0.05
"""Largest distance [m] a pair close by design may keep: a self margin above it excuses no
pair farther than this."""


@dataclass(frozen=True)
class ClosePair:
    """A checked pair of collision geometries a few millimetres apart by design.

    Attributes:
        geometries: the two geometries' indices in the robot's collision model.
        links: the links they hang on.
        largest_m: their largest coal distance over the samples [m]; a self margin above it
            holds the pair to contact only.
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
) -> tuple[ClosePair, ...]:
    """The ``pairs`` (geometry indices) apart and within :data:`CLOSE_LIMIT_M` at every sample.

    ``links`` names each geometry's link, by index.

    The configurations are drawn uniformly within ``model``'s ranges (seed 0). A pair's
    capsule bound above the limit at any of them rules it out
    (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`); coal decides the rest, configuration by
    configuration, until the pair touches or comes apart beyond the limit.
    """
    if not pairs:
        return ()
    from cpr_kin.bounds.self_bounds import bounded_pairs  # a robot with pairs of its own only

    q = sampled_configurations(model, samples, np.random.default_rng(0))
    candidates, geometry_model = bounded_pairs(model, collision_model, pairs, q, CLOSE_LIMIT_M)
    if not candidates:
        return ()
    data, geometry_data = model.createData(), geometry_model.createData()
    largest = np.zeros(len(candidates))
    alive = np.ones(len(candidates), dtype=bool)
    for x in q:
        pin.updateGeometryPlacements(model, data, geometry_model, geometry_data, x)
        for k in np.flatnonzero(alive):
            distance = pin.computeDistance(geometry_model, geometry_data, int(k)).min_distance
            largest[k] = max(largest[k], distance)
            alive[k] = 0.0 < distance < CLOSE_LIMIT_M
        if not alive.any():
            return ()
    return tuple(
        ClosePair((a, b), (links[a], links[b]), float(largest[k]))
        for k, (a, b) in enumerate(candidates)
        if alive[k]
    )
