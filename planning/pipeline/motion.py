"""What a plan moves: the start and goal configurations and the joints the waypoints move."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Motion:
    """The fixed ends of a plan and the joints its waypoints move.

    Attributes:
        q_start: start configuration [rad, m], reachable and clear of the margin.
        q_goal: goal configuration [rad, m], likewise.
        moving: indices of the joints the waypoints move; the others keep the start's values
            at every waypoint.
    """

    q_start: FloatArray
    q_goal: FloatArray
    moving: NDArray[np.intp]

    @cached_property
    def moves_every_joint(self) -> bool:
        """The waypoints move every joint, in order: a configuration is its moving joints' values."""
        return bool(np.array_equal(self.moving, np.arange(self.q_start.size)))

    def nodes(self, x: FloatArray, waypoints: int) -> FloatArray:
        """``(S, waypoints + 2, nq)`` start, waypoints and goal of candidates ``x`` ``(S, waypoints k)``."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        s = len(x)
        nodes = np.empty((s, waypoints + 2, self.q_start.size))
        nodes[:, 0], nodes[:, -1] = self.q_start, self.q_goal
        nodes[:, 1:-1] = self.q_start  # held joints keep the start's values
        nodes[:, 1:-1, self.moving] = x.reshape(s, waypoints, self.moving.size)
        return nodes

    def straight_line(self, waypoints: int) -> FloatArray:
        """The decision vector whose ``waypoints`` lie evenly on the straight line from start to goal."""
        fractions = np.arange(1, waypoints + 1) / (waypoints + 1)
        points = self.q_start + fractions[:, None] * (self.q_goal - self.q_start)
        return np.asarray(points[:, self.moving].ravel())
