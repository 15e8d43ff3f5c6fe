"""Link pairs whose shapes overlap in every configuration: touching by design, not checked.

Some URDFs give two links collision shapes that overlap wherever the joints between them are
(Alex's spine link and torso, 6-27 mm deep across the spine's ranges; iCub's torso and chest
without its SRDF). Checked, such a pair refuses every start, so no plan is possible. MoveIt's
setup assistant writes such pairs into the SRDF as "always in collision" (sampling random
configurations); an SRDF that lacks them, or no SRDF, leaves them to the planner. A pair
that collides in every one of :data:`SAMPLES` seeded configurations within the joint ranges
is taken as touching by design: :func:`overlapping_pairs` finds them, the loader leaves them
unchecked and the robot names them (:attr:`cpr_kin.Robot.overlapping_links`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import pinocchio as pin

from cpr_kin.bounds.batch_kinematics import sampled_configurations

SAMPLES = 1000
"""Seeded configurations in which a pair must collide to be taken as touching by design."""


def overlapping_pairs(
    model: Any, collision_model: Any, pairs: Sequence[tuple[int, int]], samples: int = SAMPLES
) -> tuple[tuple[int, int], ...]:
    """The ``pairs`` (geometry indices) that collide at every one of ``samples`` configurations.

    The configurations are drawn uniformly within ``model``'s ranges (seed 0). A pair's
    capsule bound above zero at any of them rules it out
    (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`);
    coal decides the rest, configuration by configuration, until the pair is found apart (by
    more than :data:`~cpr_kin.shapes.coal_queries.COLLIDE_MARGIN_AT_LEAST_M`).
    """
    if not pairs:
        return ()
    from cpr_kin.bounds.self_bounds import bounded_pairs  # a robot with pairs of its own only
    from cpr_kin.shapes.coal_queries import collide_margin_m

    q = sampled_configurations(model, samples, np.random.default_rng(0))
    candidates, geometry_model = bounded_pairs(model, collision_model, pairs, q, 0.0)
    if not candidates:
        return ()
    data, geometry_data = model.createData(), geometry_model.createData()
    margins = collide_margin_m(np.zeros((geometry_model.ngeoms,) * 2))  # coal's test at 0 may miss
    geometry_data.setSecurityMargins(geometry_model, margins, True, True)
    touching = np.ones(len(candidates), dtype=bool)
    for x in q:
        pin.computeCollisions(model, data, geometry_model, geometry_data, x, False)
        touching &= [result.isCollision() for result in geometry_data.collisionResults]
        if not touching.any():
            return ()
    return tuple(pair for pair, kept in zip(candidates, touching, strict=True) if kept)
