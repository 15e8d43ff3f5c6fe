"""Exceptions of :mod:`planning`: one base class, :class:`CprPlanError`, and two kinds below it.

Callers treat the two kinds differently:

- :class:`PlanningError` (a ``ValueError``): the input is wrong (settings, waypoints, knots,
  a scene or a file). Its message names the offending value and what is allowed: fix the
  input. The CLI exits with code 2.
- :class:`NoSolutionError` (a ``RuntimeError``): the input is valid, but the planner found
  no trajectory that passes the verification: search longer, try another seed, or loosen
  the scene. The CLI exits with code 3.

Bad robot input (a URDF, a joint vector, an obstacle) raises :class:`cpr_kin.CprKinError`,
also a ``ValueError``, which the planner lets through.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import cpr_kin as ck


class CprPlanError(Exception):
    """Base class of every exception :mod:`planning` raises.

    Pickled with its message and attributes as they are, whatever its constructor takes: an
    error raised in a worker process reaches the caller whole (``concurrent.futures``, Dask).
    """

    def __reduce__(self) -> tuple[Any, ...]:
        return _restored, (type(self), self.args, self.__dict__)


def _restored(cls: type[CprPlanError], args: tuple[Any, ...], state: dict[str, Any]) -> CprPlanError:
    """An error of class ``cls`` with ``args`` and attributes ``state``, its constructor not called."""
    error = cls.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


class PlanningError(CprPlanError, ValueError):
    """Base class of every error raised by :mod:`planning` on bad input."""


class SplineError(PlanningError):
    """Invalid spline settings, knots or node values."""


class SceneError(PlanningError):
    """A scene file is missing, not YAML, or does not follow the schema."""


class NoSolutionError(CprPlanError, RuntimeError):
    """Base class of the outcomes where valid input has no solution that was found."""


class TargetOutOfReachError(NoSolutionError):
    """No configuration puts the tool frame at a start or goal's ``tcp`` or ``pose`` (the IK's miss named)."""


class NoTrajectoryFoundError(NoSolutionError):
    """No candidate of the final population passed the verification.

    Attributes:
        certified_clearance_m: certified clearance of the best candidate [m].
        worst_time_s: when it comes closest [s].
        worst_pair: ``(robot geometry, obstacle)`` closest then.
        worst_group: the violating group.
    """

    def __init__(self, message: str, check: ck.CurveCheck) -> None:
        super().__init__(message)
        self.certified_clearance_m = check.certified_min_m
        self.worst_time_s = check.worst_time
        self.worst_pair = check.worst_pair
        self.worst_group = check.worst_group


class PayloadTooHeavyError(NoSolutionError):
    """Holding the start or goal still takes more than a joint's effort limit (joint, torque, limit named)."""


class ToolLineBrokenError(NoSolutionError):
    """A tool line cannot be followed to its end: the share achieved and why.

    Attributes:
        reason: why it breaks there.
        fraction: the share of the line (its progress, 0 to 1) the tool follows before it
            breaks, as MoveIt's Cartesian path reports it.
    """

    def __init__(self, reason: str, fraction: float) -> None:
        super().__init__(f"the tool line breaks after {fraction:.1%} of its length: {reason}")
        self.reason, self.fraction = reason, fraction


class TaskSegmentError(NoSolutionError):
    """A segment of a task has no solution: which one, and its own error.

    Attributes:
        segment: the segment's index in the task.
        cause: the segment's own error (a free motion not found, a tool line that breaks).
    """

    def __init__(self, segment: int, kind: str, cause: NoSolutionError) -> None:
        super().__init__(f"task[{segment}] ({kind}): {cause}")
        self.segment = segment
        self.cause = cause
