"""Joint limits of a serial robot: position range, velocity, acceleration and jerk."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.errors import CprKinError, UrdfError
from cpr_kin.common.names import shown
from cpr_kin.common.rest_to_rest import trapezoid_time
from cpr_kin.common.user_files import UserFileError, load_yaml
from cpr_kin.model.packages import installed

FloatArray = NDArray[np.float64]

_KINDS = ("velocity", "acceleration", "jerk")
MAX_LIMITS_BYTES = 100_000
"""Largest joint limits file [bytes] (the CPR's takes 300)."""


@dataclass(frozen=True)
class JointLimits:
    """Per-joint kinematic limits, in joint order.

    Attributes:
        names: joint names.
        lower: lower position limit [rad or m].
        upper: upper position limit [rad or m].
        velocity: maximum absolute velocity [rad/s or m/s].
        acceleration: maximum absolute acceleration [rad/s^2 or m/s^2].
        jerk: maximum absolute jerk [rad/s^3 or m/s^3].
        effort: the URDF's effort limits [N m or N], kept (not yet planned with); ``None``
            when unknown.

    """

    names: tuple[str, ...]
    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray
    effort: FloatArray | None = None

    def __post_init__(self) -> None:
        n = len(self.names)
        for field in ("lower", "upper", *_KINDS):
            value = np.array(getattr(self, field), dtype=float)
            if value.shape != (n,):
                raise CprKinError(
                    f"joint limits '{field}' has shape {value.shape}; expected ({n},), "
                    f"one value per joint {list(self.names)}"
                )
            if not np.all(np.isfinite(value)):
                raise CprKinError(f"joint limits '{field}' = {value.tolist()} must be finite")
            value.setflags(write=False)
            object.__setattr__(self, field, value)
        for i, name in enumerate(self.names):
            if not self.lower[i] <= self.upper[i]:
                raise CprKinError(
                    f"joint '{name}': lower limit {self.lower[i]} exceeds upper limit {self.upper[i]}"
                )
            for kind in _KINDS:
                if not getattr(self, kind)[i] > 0.0:
                    raise CprKinError(f"joint '{name}': {kind} limit {getattr(self, kind)[i]} must be > 0")

    @property
    def range(self) -> FloatArray:
        """Width of each joint's position range [rad or m]."""
        return self.upper - self.lower

    @property
    def speed_scales(self) -> FloatArray:
        """Each joint's velocity limit over the fastest joint's, in (0, 1].

        The joint-space metric in which a step's size is about the time it takes: a damped
        least-squares step on the Jacobian's columns scaled by these (and the step scaled back)
        moves the fast joints rather than a slow one (a torso lift of 0.013 m/s beside an arm
        of 2 rad/s), whatever their units. Joints of equal limits all get 1: the plain step.
        """
        return np.asarray(self.velocity / self.velocity.max())

    @property
    def speeds_differ(self) -> bool:
        """Whether some joint is slower than the fastest (its steps least in time are not its plain ones)."""
        return bool(np.any(self.velocity < self.velocity.max()))

    def move_time_s(self, change: FloatArray) -> FloatArray:
        """``(...)`` the shortest rest-to-rest time [s] of a joint move by ``change`` ``(..., nq)`` [rad, m].

        The slowest joint's :func:`trapezoid_time` under the velocity and acceleration limits:
        the others can be slowed to arrive with it.
        """
        return np.asarray(trapezoid_time(change, self.velocity, self.acceleration).max(axis=-1))

    def index(self, name: str) -> int:
        """Index of joint ``name``; raises :class:`CprKinError` naming the known joints."""
        try:
            return self.names.index(name)
        except ValueError:
            raise CprKinError(f"unknown joint '{name}'; the robot's joints are {list(self.names)}") from None


LIMITS_NAMES = ("{stem}_limits.yaml", "limits.yaml")
"""Names of the limits file looked for beside a URDF, in order (``{stem}``: the URDF's name
without ``.urdf``)."""


DEFAULT_ACCELERATION_PER_S = 2.0
"""Where a limits file gives no acceleration: ``a = 2 v`` per second (the velocity limit
reached in 0.5 s), below what arms' makers publish (Franka's Panda: 7-9 v)."""
DEFAULT_JERK_PER_S = 10.0
"""Where a limits file gives no jerk: ``j = 10 a`` per second (the acceleration limit reached
in 0.1 s), below what arms' makers publish (Franka's Panda: 500 a)."""


@dataclass(frozen=True)
class DynamicLimits:
    """Velocity, acceleration and jerk limits of the planned joints, and where they came from.

    Attributes:
        acceleration: per joint [rad/s^2 or m/s^2].
        jerk: per joint [rad/s^3 or m/s^3].
        source: the limits file read, or ``None`` when none was found.
        defaulted: the joints whose acceleration or jerk is a default
            (:data:`DEFAULT_ACCELERATION_PER_S`, :data:`DEFAULT_JERK_PER_S`).
        velocity: per joint [rad/s or m/s]: the URDF's, or the file's where the URDF gives
            none (0 or no ``velocity``); ``None``: the URDF's throughout.
    """

    acceleration: FloatArray
    jerk: FloatArray
    source: Path | None
    defaulted: tuple[str, ...]
    velocity: FloatArray | None = None


def default_limits(velocity: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The default acceleration and jerk limits of joints with ``velocity`` limits."""
    acceleration = DEFAULT_ACCELERATION_PER_S * np.asarray(velocity, dtype=float)
    return acceleration, DEFAULT_JERK_PER_S * acceleration


def limits_candidates(urdf_path: Path, names: tuple[str, ...] = LIMITS_NAMES) -> list[Path]:
    """The limits files looked for beside the URDF at ``urdf_path``, in order."""
    return [urdf_path.parent / name.format(stem=urdf_path.stem) for name in names]


def find_limits_file(
    urdf_path: Path, default: Path | None = None, names: tuple[str, ...] = LIMITS_NAMES
) -> Path | None:
    """The acceleration and jerk limits file of the URDF at ``urdf_path``, if any.

    The first of ``names`` (default :data:`LIMITS_NAMES`) that exists beside the URDF, else
    ``default`` (``None``: the defaults of :func:`default_limits` apply).
    """
    for candidate in limits_candidates(urdf_path, names):
        if candidate.is_file():
            return candidate
    return default


def read_limits_file(path: Path) -> dict[Any, Any]:
    """The mapping of a limits file, read safely; its entries are checked by :func:`read_dynamic_limits`.

    Raises:
        UrdfError: the file is unreadable, not YAML, or not a mapping of joint names.
    """
    try:
        raw = load_yaml(path, MAX_LIMITS_BYTES, "joint limits file")
    except UserFileError as exc:
        raise UrdfError(str(exc)) from None
    if not isinstance(raw, dict):
        raise UrdfError(
            f"joint limits file '{path}' must map joint names to limits ({{joint: {{acceleration: ..., "
            f"jerk: ...}}}}), not {type(raw).__name__}"
        )
    return raw


def read_dynamic_limits(
    path: Path | None,
    names: tuple[str, ...],
    urdf_velocity: FloatArray,
    known: tuple[str, ...] = (),
    urdf: Path | None = None,
) -> DynamicLimits:
    """Read acceleration and jerk limits from a limits file (the format of ``cpr_limits.yaml``).

    The file maps joint names to ``{velocity, acceleration, jerk}``; ``velocity`` is optional
    and, when given, must agree with the URDF's, unless the URDF gives none (0, as many
    description-only URDFs do): then the file's is the joint's. A joint the file leaves out,
    or whose acceleration or jerk it leaves out, gets :func:`default_limits` of its velocity;
    with no file (``path`` ``None``) every joint does.

    Args:
        path: the file, or ``None``.
        names: the planned joints, in order.
        urdf_velocity: their velocity limits from the URDF.
        known: every joint of the URDF (the file may name held joints too); default ``names``.
        urdf: the URDF, whose velocity limits a message may suggest editing (not an installed one).

    Raises:
        UrdfError: the file is unreadable, names a joint the URDF lacks, or holds a value
            that is not a number, or a velocity that disagrees with the URDF's; a joint has a
            velocity limit from neither.
    """
    urdf_velocity = np.asarray(urdf_velocity, dtype=float)
    if path is None:
        _require_velocity(names, urdf_velocity, None, urdf)
        acc_default, jerk_default = default_limits(urdf_velocity)
        return DynamicLimits(acc_default, jerk_default, None, tuple(names))
    raw = read_limits_file(path)
    unknown = sorted(set(map(str, raw)) - set(names) - set(known))
    if unknown:
        listed = ", ".join(repr(n)[:40] for n in unknown[:3]) + (", ..." if len(unknown) > 3 else "")
        raise UrdfError(
            f"joint limits file '{path}' names unknown joint(s) [{listed}]; the planned joints are "
            f"{list(names)} (the URDF's other joints may be named too)"
        )
    velocity = urdf_velocity.copy()
    for i, name in enumerate(names):  # the file's velocity where the URDF gives none
        entry = raw.get(name)
        if not velocity[i] > 0.0 and isinstance(entry, dict) and _is_number(entry.get("velocity")):
            velocity[i] = float(entry["velocity"])
    _require_velocity(names, velocity, path, urdf)
    acc, jerk = default_limits(velocity)
    defaulted = []
    for i, name in enumerate(names):
        entry = raw.get(name, {})
        if not isinstance(entry, dict):
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' needs a mapping {{acceleration: ..., jerk: ...}}"
            )
        if {"acceleration", "jerk"} - set(entry):
            defaulted.append(name)
        extra = sorted(set(entry) - set(_KINDS))
        if extra:
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' has unknown key(s) {extra}; "
                f"allowed: {list(_KINDS)}"
            )
        defaults = {"velocity": velocity[i], "acceleration": acc[i], "jerk": jerk[i]}
        values: dict[str, Any] = {kind: entry.get(kind, defaults[kind]) for kind in _KINDS}
        for kind, value in values.items():
            if isinstance(value, bool) or not isinstance(value, int | float) or not 0 < value < math.inf:
                raise UrdfError(
                    f"joint limits file '{path}': joint '{name}' {kind} = {shown(value)} "
                    "must be a finite number > 0"
                )
        acc[i], jerk[i], vel = float(values["acceleration"]), float(values["jerk"]), float(values["velocity"])
        if not np.isclose(vel, velocity[i]):
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' velocity {vel} disagrees with "
                f"the URDF's {urdf_velocity[i]}; edit one so that they match"
            )
    given = None if np.array_equal(velocity, urdf_velocity) else velocity
    return DynamicLimits(acc, jerk, path, tuple(defaulted), given)


def _is_number(value: Any) -> bool:
    return isinstance(value, int | float) and not isinstance(value, bool)


def _require_velocity(
    names: tuple[str, ...], velocity: FloatArray, path: Path | None, urdf: Path | None
) -> None:
    """Refuse joints with no velocity limit > 0, naming them and where to give one.

    The URDF is suggested only where it is the user's to edit, not inside an installed package.
    """
    missing = [name for name, v in zip(names, velocity, strict=True) if not v > 0.0]
    if missing:
        where = f"the limits file '{path}'" if path is not None else "a limits file (limits=...)"
        in_urdf = "" if urdf is not None and installed(urdf) else "<limit velocity=...> in the URDF, or "
        raise UrdfError(
            f"joint(s) {missing} have no velocity limit (the URDF's is 0 or missing); the timing needs "
            f"one > 0 [rad/s or m/s]: give {in_urdf}'velocity' in {where}"
        )
