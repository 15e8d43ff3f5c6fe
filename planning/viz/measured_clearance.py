"""The clearance a task's certified checks measured, segment by segment: what colours its path.

A task changes its world as it goes (:mod:`planning.task.holding`: what the robot carries, an
obstacle taken, an object left), so no one world measures its whole path. Each segment's
verification measured it with the world as it was then; :func:`task_clearance` puts those
samples on the task's clock for the viewer (:meth:`planning.viz.viewer.Viewer.show_plan`).
Headless.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from planning.task.task_plan import TaskMotion

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class MeasuredClearance:
    """Clearance measured at instants of a trajectory.

    Attributes:
        times_s: ``(K,)`` increasing instants [s].
        clearance_m: ``(K,)`` the least clearance of the robot (and what it carries) from the
            obstacles there [m].
    """

    times_s: FloatArray
    clearance_m: FloatArray

    def at(self, times_s: FloatArray) -> FloatArray:
        """The clearance at ``times_s`` [s], linear between the measured instants [m]."""
        return np.interp(times_s, self.times_s, self.clearance_m)


def task_clearance(task: TaskMotion) -> MeasuredClearance:
    """The samples of every segment's certified check, on the task's clock.

    A check's instants are on the clock of the motion it is part of (motions the task does not
    stop between are timed as one, :mod:`planning.task.task_timing`), its first the segment's
    start: each is moved to start at the segment's ``t0``.
    """
    times, clearance = [], []
    for segment in task.segments:
        if segment.verification is not None:
            check = segment.verification.check
            instants = np.asarray(check.times)
            times.append(segment.t0 + (instants - instants[0]))
            clearance.append(np.asarray(check.clearance_m).min(axis=1))
    instants = np.concatenate(times)
    order = np.argsort(instants, kind="stable")
    return MeasuredClearance(instants[order], np.concatenate(clearance)[order])
