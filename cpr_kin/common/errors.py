"""Exceptions of :mod:`cpr_kin`.

Every error caused by user input (a URDF, a joint vector, a pose, an obstacle) is a
:class:`CprKinError`, whose message names the offending value, what is allowed, and,
where there is one, the fix. Callers catch this one base class.
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
