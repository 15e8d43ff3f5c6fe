"""Exceptions of :mod:`cpr_kin`.

Every error caused by user input (a URDF, a joint vector, a pose, an obstacle) is a
:class:`CprKinError`, whose message names the offending value, what is allowed, and,
where there is one, the fix. Callers catch this one base class; :class:`CheckStoppedError`, a
check its caller stopped, derives from it too.
"""

from __future__ import annotations


class CprKinError(ValueError):
    """Base class of every error raised by :mod:`cpr_kin` on bad input."""


class UrdfError(CprKinError):
    """The URDF is missing, malformed, or asks what the planner does not support."""


class JointLimitError(CprKinError):
    """A joint value lies outside its limits, or is not finite."""


class UnreachableError(JointLimitError):
    """An inverse-kinematics target cannot be reached within the joint limits."""


class ObstacleError(CprKinError):
    """An obstacle description is invalid (shape, size, pose or mesh file)."""


class IkMissError(UnreachableError):
    """A numerical inverse kinematics found no configuration within the target's tolerance."""


class CheckStoppedError(CprKinError):
    """A certified check was stopped by its caller (its ``stop`` said so) before its verdict.

    Nothing is certified: the caller treats the curve as not verified (a plan past its time
    limit, :mod:`planning.pipeline.deadline`).
    """
