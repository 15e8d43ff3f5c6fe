"""Junctions that do not stop: a task's consecutive motions joined into one path and timed as one.

The robot must stop where the task says so: at a wait, an attach or a detach (a grasp), and
at the task's ends. Between two motions their paths may be joined into one, C3, and timed as
one (:func:`~planning.curves.on_path_timing.time_on_path_marked`), so that the robot passes the
junction without stopping; the caller joins them where that is sooner than a stop
(:mod:`planning.task.task_timing`). A line and a path under an orientation constraint are *rigid*:
followed as planned. A free motion's path may be bent near a junction: its last (or first)
:data:`BLEND_SHARE` is replaced by a septic bridge whose ends take the position and first three
derivatives of the paths it joins (:func:`~planning.curves.path_pieces.bridge`), so that the
whole is C3 and still passes through the junction's configuration (a free motion still ends at
its goal); between two free motions the junction is passed along the chord of their bridges'
far ends. Two rigid paths cannot be joined without leaving one of them: a run of motions is cut
there (:func:`runs`). The caller verifies the joined motion segment by segment, and keeps the
stops where it fails.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planning.curves.interpolating_spline import chord_lengths, chord_parameter, spline_through
from planning.curves.on_path_timing import MarkedMotion, time_on_path_marked
from planning.curves.path_pieces import bridge, ends, joined_paths, piece, rescaled
from planning.curves.path_timing import NODE_STEP_S
from planning.curves.torque_limits import TorqueModel
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

CHORD_SAMPLES = 129
"""Samples of a free motion's path reparameterised by its chord length (:func:`by_chord`)."""
BLEND_SHARE = 0.5
"""The share of a free motion's path a bridge replaces at a junction that does not stop."""
KEPT_SHARE = 0.2
"""The share of a free motion's path kept between two bridges, where it is bridged at both ends."""


@dataclass(frozen=True)
class Piece:
    """One motion's geometric path, and whether it must be followed as planned.

    Attributes:
        path: the path, over any parameter interval; its ends are the motion's.
        rigid: a line or a path under an orientation constraint (never bent).
    """

    path: Trajectory
    rigid: bool


def runs(rigid: Sequence[bool | None]) -> list[list[int]]:
    """The runs of two or more motions that may be joined: ``rigid[i]`` ``None`` for a segment that stops.

    A run is cut where two rigid motions meet (and at every segment that stops).
    """
    found: list[list[int]] = []
    current: list[int] = []
    for index, kind in enumerate(rigid):
        if kind is None or (current and kind and rigid[current[-1]]):
            if len(current) > 1:
                found.append(current)
            current = [] if kind is None else [index]
        else:
            current.append(index)
    if len(current) > 1:
        found.append(current)
    return found


def joined_motion(
    pieces: Sequence[Piece],
    limits: tuple[FloatArray, FloatArray, FloatArray],
    torque: TorqueModel | None = None,
    node_step_s: float = NODE_STEP_S,
) -> MarkedMotion:
    """``pieces`` joined into one C3 path (see above) and timed as one; ``times``: the junctions'.

    Raises:
        PlanningError: two rigid pieces meet, or the joined path cannot be timed.
    """
    if any(before.rigid and after.rigid for before, after in itertools.pairwise(pieces)):
        raise PlanningError("two rigid paths (lines, constrained motions) cannot be joined without a stop")
    paths_by_chord = [p.path if p.rigid else by_chord(p.path) for p in pieces]
    lengths = [_length(path) for path in paths_by_chord]
    starts = np.concatenate([[0.0], np.cumsum(lengths)])
    paths = [
        rescaled(path, float(s), length)
        for path, s, length in zip(paths_by_chord, starts[:-1], lengths, strict=True)
    ]
    cut_start = [0.0] * len(pieces)  # how much of each path's start and end a bridge replaces
    cut_end = [0.0] * len(pieces)
    for i in range(len(pieces) - 1):
        if not pieces[i].rigid:
            cut_end[i] = BLEND_SHARE * lengths[i]
        if not pieces[i + 1].rigid:
            cut_start[i + 1] = BLEND_SHARE * lengths[i + 1]
    for i, length in enumerate(lengths):  # a free motion bridged at both ends keeps a share between
        if cut_start[i] + cut_end[i] > (1.0 - KEPT_SHARE) * length:
            cut_start[i] = min(cut_start[i], 0.5 * (1.0 - KEPT_SHARE) * length)
            cut_end[i] = min(cut_end[i], 0.5 * (1.0 - KEPT_SHARE) * length)
    parts: list[Trajectory] = []
    for i, path in enumerate(paths):
        a, b = starts[i] + cut_start[i], starts[i + 1] - cut_end[i]
        if i > 0:
            parts += _bridge_in(paths[i - 1], path, float(starts[i]), cut_end[i - 1], cut_start[i])
        parts.append(path if (a, b) == (starts[i], starts[i + 1]) else piece(path, a, b))
    return time_on_path_marked(joined_paths(parts), limits, starts[1:-1], node_step_s, torque)


def by_chord(path: Trajectory, samples: int = CHORD_SAMPLES) -> Trajectory:
    """``path`` again, its parameter about its length: a quintic through samples at their chord lengths.

    A free motion's path comes parameterised by its own time, slow near its ends: its
    derivatives there hold its accelerations, which a bridge would inherit as wiggles. By its
    chord length the derivatives hold its shape only (``|q'|`` about 1).
    """
    points = path(np.linspace(path.knots[0], path.knots[-1], samples))
    chords = np.linalg.norm(np.diff(points, axis=0), axis=1)
    keep = np.concatenate([[True], chords > 1e-12 * max(float(chords.sum()), 1.0)])
    points = points[keep]
    return spline_through(chord_parameter(points), points)


def _length(path: Trajectory) -> float:
    """The path's length in joint space, summed over 64 chords (its parameter's scale in the joined path)."""
    return max(float(chord_lengths(path(np.linspace(path.knots[0], path.knots[-1], 65)))[-1]), 1e-9)


def _bridge_in(
    before: Trajectory, after: Trajectory, junction: float, end_cut: float, start_cut: float
) -> list[Trajectory]:
    """The bridges about ``junction``: over the end of ``before`` and/or the start of ``after``."""
    q = before(np.array([junction]))[0]
    if end_cut and start_cut:  # two free motions: through the junction along the chord
        a, b = junction - end_cut, junction + start_cut
        chord = (after(np.array([b]))[0] - before(np.array([a]))[0]) / (b - a)
        middle = np.stack([q, chord, np.zeros_like(q), np.zeros_like(q)])
        first = bridge(ends(before, a), middle, a, end_cut)
        return [first, bridge(middle, ends(after, b), junction, start_cut)]
    if end_cut:
        return [bridge(ends(before, junction - end_cut), ends(after, junction), junction - end_cut, end_cut)]
    return [bridge(ends(before, junction), ends(after, junction + start_cut), junction, start_cut)]
