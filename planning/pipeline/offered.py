"""A candidate's timings: each a :class:`Timing`, offered in order of preference (:class:`Offered`).

The duration rules of :mod:`planning.pipeline.timing` compute them; the choice stage
(:mod:`planning.pipeline.choose`) verifies them in this order, and asks for the later ones
only when the first has failed: they are computed then.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory

Method = Literal["fixed", "fastest", "narrowed", "uniform", "through_path", "stop_and_go"]


@dataclass(frozen=True)
class Timing:
    """One timing of a candidate's path.

    Attributes:
        trajectory: the timed trajectory.
        method: ``fixed`` (the scene's duration), ``fastest``, ``narrowed`` or ``uniform``
            (module docstring); or the sampling planner's path followed
            (:mod:`planning.pipeline.path_following`): ``through_path`` (a spline through its
            vertices, timed by the scene's duration rule) or ``stop_and_go`` (the path as it is).
        fit: the spline through the nodes that was timed (before timing).
        stretched: a fixed duration broke a limit and was stretched.
        time_s: wall time of computing it [s].
    """

    trajectory: Trajectory
    method: Method
    fit: SplineFit
    stretched: bool
    time_s: float


class Offered:
    """A candidate's timings in order of preference: the first at once, the others when first asked for.

    Args:
        first: the preferred timing (the shortest).
        later: computes the others, shortest first; called at most once.
    """

    def __init__(self, first: Timing, later: Callable[[], list[Timing]] = list) -> None:
        self.first, self._later = first, later

    @cached_property
    def others(self) -> list[Timing]:
        """The timings after the first, shortest first (computed on first access)."""
        return self._later()

    @property
    def all(self) -> list[Timing]:
        """Every timing, in order of preference."""
        return [self.first, *self.others]

    def of(self, method: Method) -> Timing | None:
        """The timing computed by ``method``, if it is offered (the others computed only if needed)."""
        if self.first.method == method:
            return self.first
        return next((timing for timing in self.others if timing.method == method), None)
