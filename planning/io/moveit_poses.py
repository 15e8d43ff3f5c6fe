"""The geometry of MoveIt's messages: numbers, vectors, quaternions, poses and transforms.

Poses take both YAML forms seen in the wild: lists (``position: [x, y, z]``, ``orientation:
[x, y, z, w]``, as MotionBenchMaker writes) and mappings (``{x: .., y: .., z: ..}``, as
``rostopic echo`` writes). A quaternion follows one rule (:func:`planning.validation.unit_quaternion`:
rounding normalised, anything else refused), but for all zeros, which MoveIt reads as the
identity: so is it read here, and :func:`zero_quaternions` lists where, for the summary.
"""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
import pinocchio as pin
from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field

from planning.validation import unit_quaternion

Number = Annotated[float, Field(allow_inf_nan=False)]


def _vector(keys: str) -> Any:
    """A list of numbers, also given as a mapping with the keys ``keys`` (``"xyz"``, ``"xyzw"``)."""

    def as_list(value: Any) -> Any:
        if isinstance(value, dict) and set(value) <= set(keys):
            if keys == "xyzw" and "w" not in value and any(value.get(k, 0.0) != 0.0 for k in "xyz"):
                raise ValueError(
                    f"{value} gives no w: ROS 1 reads it as 0, ROS 2 as 1, two rotations; give w"
                )
            default = {"w": 1.0} if keys == "xyzw" else {}  # x, y, z of 0 and no w: identity in both
            return [value.get(k, default.get(k, 0.0)) for k in keys]
        return value

    return BeforeValidator(as_list)


def _rotation(xyzw: list[float]) -> list[float]:
    """A quaternion of norm 1 (within rounding: normalised), or all zeros (MoveIt's identity).

    :func:`zero_quaternions` lists the zeros; any other quaternion is refused.
    """
    return xyzw if not any(xyzw) else list(unit_quaternion(xyzw))


Vector3 = Annotated[list[Number], Field(min_length=3, max_length=3), _vector("xyz")]
Quaternion = Annotated[
    list[Number], Field(min_length=4, max_length=4), _vector("xyzw"), AfterValidator(_rotation)
]


class Message(BaseModel):
    """A message: unknown keys refused, every field optional as in ROS (defaults: empty, zero).

    Strict: a number must be a number (not ``"0.1"``), a flag ``true`` or ``false`` (not ``yes``).
    """

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)


class Pose(Message):
    """``geometry_msgs/Pose``."""

    position: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    orientation: Quaternion = Field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])

    def matrix(self) -> np.ndarray:
        """The ``(4, 4)`` homogeneous transform [m]; an orientation of all zeros is the identity."""
        transform = np.eye(4)
        transform[:3, :3] = rotation_matrix(self.orientation)
        transform[:3, 3] = self.position
        return transform


def rotation_matrix(xyzw: list[float]) -> np.ndarray:
    """The rotation of a validated :data:`Quaternion`: all zeros are the identity, as MoveIt reads them."""
    if not any(xyzw):
        return np.eye(3)
    x, y, z, w = xyzw
    return np.asarray(pin.Quaternion(w, x, y, z).normalized().matrix())


def zero_quaternions(message: BaseModel, path: str) -> list[str]:
    """The orientations of all zeros in ``message`` (itself at ``path``), each by its field path."""
    found = []
    for name, value in message:
        if name in ("orientation", "rotation") and isinstance(value, list) and not any(value):
            found.append(f"{path}.{name}")
        children = [(f"{path}.{name}", value)] if isinstance(value, BaseModel) else []
        if isinstance(value, list):
            children = [(f"{path}.{name}[{k}]", v) for k, v in enumerate(value) if isinstance(v, BaseModel)]
        for where, child in children:
            found += zero_quaternions(child, where)
    return found


class Transform(Message):
    """``geometry_msgs/Transform``."""

    translation: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])
    rotation: Quaternion = Field(default_factory=lambda: [0.0, 0.0, 0.0, 1.0])

    def matrix(self) -> np.ndarray:
        """The ``(4, 4)`` homogeneous transform [m]."""
        return Pose(position=self.translation, orientation=self.rotation).matrix()
