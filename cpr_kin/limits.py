"""Joint limits of a serial robot: position range, velocity, acceleration and jerk."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.errors import CprKinError, UrdfError
from cpr_kin.user_files import UserFileError, load_yaml

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

    """

    names: tuple[str, ...]
    lower: FloatArray
    upper: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray

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

    def index(self, name: str) -> int:
        """Index of joint ``name``; raises :class:`CprKinError` naming the known joints."""
        try:
            return self.names.index(name)
        except ValueError:
            raise CprKinError(f"unknown joint '{name}'; the robot's joints are {list(self.names)}") from None


LIMITS_NAMES = ("{stem}_limits.yaml", "limits.yaml")
"""Names of the limits file looked for beside a URDF, in order (``{stem}``: the URDF's name
without ``.urdf``)."""


def find_limits_file(
    urdf_path: Path, default: Path | None = None, names: tuple[str, ...] = LIMITS_NAMES
) -> Path:
    """The acceleration and jerk limits file of the URDF at ``urdf_path``.

    The first of ``names`` (default :data:`LIMITS_NAMES`) that exists beside the URDF, else
    ``default``.

    Raises:
        UrdfError: none exists and there is no default; the message names every path looked for.
    """
    candidates = [urdf_path.parent / name.format(stem=urdf_path.stem) for name in names]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    if default is not None:
        return default
    looked = ", ".join(f"'{c}'" for c in candidates)
    raise UrdfError(
        f"no acceleration and jerk limits for URDF '{urdf_path}': looked for {looked}; write one "
        "(joint: {velocity, acceleration, jerk}, the format of cpr_kin/urdf/cpr_limits.yaml) or pass its path"
    )


def read_dynamic_limits(
    path: Path, names: tuple[str, ...], urdf_velocity: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Read acceleration and jerk limits from a limits file (the format of ``cpr_limits.yaml``).

    The file maps each joint name to ``{velocity, acceleration, jerk}``; ``velocity`` is
    optional and, when given, must agree with the URDF's.

    Returns:
        (acceleration, jerk) arrays in the order of ``names``.

    """
    try:
        raw = load_yaml(path, MAX_LIMITS_BYTES, "joint limits file")
    except UserFileError as exc:
        raise UrdfError(str(exc)) from None
    if not isinstance(raw, dict):
        raise UrdfError(f"joint limits file '{path}' must map joint names to limits")
    unknown = sorted(set(map(str, raw)) - set(names))
    if unknown:
        listed = ", ".join(repr(n)[:40] for n in unknown[:3]) + (", ..." if len(unknown) > 3 else "")
        known = list(names)
        raise UrdfError(
            f"joint limits file '{path}' names unknown joint(s) [{listed}]; the robot's are {known}"
        )
    acc = np.empty(len(names))
    jerk = np.empty(len(names))
    for i, name in enumerate(names):
        entry = raw.get(name)
        if not isinstance(entry, dict) or {"acceleration", "jerk"} - set(entry):
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' needs {{acceleration: ..., jerk: ...}}"
            )
        extra = sorted(set(entry) - set(_KINDS))
        if extra:
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' has unknown key(s) {extra}; "
                f"allowed: {list(_KINDS)}"
            )
        values: dict[str, Any] = {
            kind: entry.get(kind, urdf_velocity[i] if kind == "velocity" else None) for kind in _KINDS
        }
        for kind, value in values.items():
            if isinstance(value, bool) or not isinstance(value, int | float):
                shown = repr(value) if len(repr(value)) <= 40 else repr(value)[:37] + "..."
                raise UrdfError(
                    f"joint limits file '{path}': joint '{name}' {kind} = {shown} must be a number"
                )
        acc[i], jerk[i], vel = float(values["acceleration"]), float(values["jerk"]), float(values["velocity"])
        if not np.isclose(vel, urdf_velocity[i]):
            raise UrdfError(
                f"joint limits file '{path}': joint '{name}' velocity {vel} disagrees with "
                f"the URDF's {urdf_velocity[i]}; edit one so that they match"
            )
    return acc, jerk
