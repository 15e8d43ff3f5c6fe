"""Whether a trajectory is continuous in position, velocity, acceleration and jerk (C3) at its knots.

One rule for every reader: ``cpr-plan check`` reports a jump as a failure, ``export`` refuses
to write one for a controller, ``show`` warns of it.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from planning.curves.hermite import CONTINUITY
from planning.curves.trajectory import DERIVATIVE_NAMES, Trajectory

CONTINUITY_TOLERANCE = 1e-6
"""Largest jump of position, velocity, acceleration or jerk at a knot of a C3 trajectory
(:meth:`~planning.curves.trajectory.Trajectory.knot_jumps`): relative to the magnitudes
summed there, or to the joint's largest |value| of that derivative over the trajectory
(at least 1 rad/s^r or m/s^r), whichever is larger: rounding, in our file or another
tool's, must not count, also at a knot where the robot rests and the local magnitudes vanish."""


def discontinuity(
    trajectory: Trajectory, joint_names: Sequence[str], units: Sequence[str] | None = None
) -> str | None:
    """The worst jump at a knot beyond :data:`CONTINUITY_TOLERANCE`, as a sentence, or ``None``.

    Args:
        trajectory: the trajectory.
        joint_names: its joints, in order, to name the one that jumps.
        units: each joint's position unit (``"rad"``, ``"m"``); ``None``: "rad or m".
    """
    jump, relative = trajectory.knot_jumps(CONTINUITY + 1)
    peak = np.stack([trajectory.extrema(r).peak for r in range(CONTINUITY + 1)], axis=1)  # (nj, r)
    relative = np.where(jump > CONTINUITY_TOLERANCE * np.maximum(peak, 1.0), relative, 0.0)
    if relative.size == 0 or relative.max() <= CONTINUITY_TOLERANCE:
        return None
    knot, joint, r = (int(i) for i in np.unravel_index(int(np.argmax(relative)), relative.shape))
    per_time = "" if r == 0 else "/s" if r == 1 else f"/s^{r}"
    unit = (units[joint] if units is not None else "rad or m") + per_time
    where = f"t = {trajectory.knots[knot + 1]:.4g} s (knot {knot + 1})"
    return (
        f"is not continuous (C3) at {where}: the {DERIVATIVE_NAMES[r]} of joint '{joint_names[joint]}' "
        f"jumps by {jump[knot, joint, r]:.3g} {unit}"
    )
