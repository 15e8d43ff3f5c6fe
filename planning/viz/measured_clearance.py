"""The clearance a task's path keeps, segment by segment in its own world: what colours its path.

A task changes its world as it goes (:mod:`planning.task.holding`: what the robot carries, an
obstacle taken, an object left), so no one world measures its whole path. Each segment's
verification measured it with the world as it was then; :func:`task_clearance` puts those
samples on the task's clock for the viewer (:meth:`planning.viz.viewer.Viewer.show_plan`),
with the closest pair at the least of them found in that segment's world. A task read back
from its trajectory file has no checks to show: :func:`sampled_clearance` samples it in the
world of each instant instead. Headless.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.pipeline.problem import scene_robot, scene_world

if TYPE_CHECKING:
    from collections.abc import Sequence

    from planning.curves.trajectory import Trajectory
    from planning.pipeline.scene import Scene
    from planning.task.task_plan import TaskMotion

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class MeasuredClearance:
    """Clearance measured at instants of a trajectory.

    Attributes:
        times_s: ``(K,)`` increasing instants [s].
        clearance_m: ``(K,)`` the least clearance of the robot (and what it carries) from the
            obstacles there [m].
        closest: the robot-obstacle pair closest at the least of them (:attr:`worst_time_s`),
            in the world that measured it; ``None``: not known.
    """

    times_s: FloatArray
    clearance_m: FloatArray
    closest: ck.PairDistance | None = None

    @property
    def worst_time_s(self) -> float:
        """The instant of the least measured clearance [s]."""
        return float(self.times_s[int(np.argmin(self.clearance_m))])

    def at(self, times_s: FloatArray) -> FloatArray:
        """The clearance at ``times_s`` [s], linear between the measured instants [m]."""
        return np.interp(times_s, self.times_s, self.clearance_m)


def task_clearance(task: TaskMotion) -> MeasuredClearance:
    """The samples of every segment's certified check, on the task's clock, and the closest pair.

    A check's instants are on the clock of the motion it is part of (motions the task does not
    stop between are timed as one, :mod:`planning.task.task_timing`), its first the segment's
    start: each is moved to start at the segment's ``t0``. The closest pair at the least
    clearance is that segment's world's (what the robot carries then, among the obstacles then).
    """
    times, clearance, owner = [], [], []
    worlds: list[ck.CollisionWorld | None] = []
    for segment in task.segments:
        if segment.verification is not None:
            check = segment.verification.check
            instants = np.asarray(check.times)
            times.append(segment.t0 + (instants - instants[0]))
            clearance.append(np.asarray(check.clearance_m).min(axis=1))
            owner.append(np.full(len(instants), len(worlds)))  # the sample's segment
            worlds.append(segment.world)
    instants = np.concatenate(times)
    order = np.argsort(instants, kind="stable")
    measured = MeasuredClearance(instants[order], np.concatenate(clearance)[order])
    world = worlds[int(np.concatenate(owner)[order][int(np.argmin(measured.clearance_m))])]
    if world is None:
        return measured
    q_worst = task.trajectory(measured.worst_time_s)  # where the least was measured, in its world
    return dataclasses.replace(measured, closest=world.clearance(q_worst).closest)


def sampled_clearance(
    robot: ck.Robot, trajectory: Trajectory, scenes: Sequence[tuple[float, Scene]], samples: int = 400
) -> MeasuredClearance:
    """The clearance of ``trajectory`` at ``samples`` instants, each in the world of its time.

    ``scenes``: ``(t, scene)`` in time order, the first at the trajectory's start: from ``t``
    [s] on, ``robot`` (as loaded, carrying nothing) carries that scene's payload among its
    obstacles (a task's: its start, then :func:`planning.viz.carried_objects.recorded_scenes`).
    The closest pair at the least clearance is that instant's world's.
    """
    times = np.linspace(trajectory.knots[0], trajectory.knots[-1], samples)
    state = np.searchsorted([t for t, _ in scenes], times, side="right") - 1
    clearance, worlds = np.full(samples, np.inf), {}
    for k, (_, scene) in enumerate(scenes):
        rows = np.flatnonzero(state == k)
        if rows.size:
            worlds[k] = scene_world(scene, scene_robot(scene, robot))
            clearance[rows] = worlds[k].clearance_batch(trajectory(times[rows])).min_clearance_m
    worst = int(np.argmin(clearance))
    closest = worlds[int(state[worst])].clearance(trajectory(times[worst])).closest
    return MeasuredClearance(times, clearance, closest)
