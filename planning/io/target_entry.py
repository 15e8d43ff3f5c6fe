"""A scene file's ``start:`` and ``goal:`` entries, to and from :class:`~planning.pipeline.target.Target`.

```yaml
start: {q: [0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785]}     # the planned joints, in order
start: {q: {panda_joint1: 0.0, panda_joint2: -0.785, ...}}     # or every one by name
goal:  {tcp: [0.5, 0.2, 0.4]}                                  # a position of the tool frame [m]
goal:  {tcp: [0.5, 0.2, 0.4], hold: {panda_joint7: 0.785}}     # with joints held [rad, m]
goal:  {pose: {xyz: [0.5, 0.2, 0.4], quat_xyzw: [1, 0, 0, 0]}, tolerance_m: 0.001}
goal:  {pose: {xyz: [0.5, 0.2, 0.4], rpy: [3.1416, 0, 0]}, tolerance_rad: 0.01}
```
"""

from typing import Annotated, Any, Self

import numpy as np
import pinocchio as pin
from pydantic import AfterValidator, Field, Tag, model_validator

from planning.io.schema_types import (
    BY_KIND,
    MAPPING_TAG,
    OTHER_TAG,
    Angle,
    Name,
    Point,
    Strict,
    Turn,
    between,
)
from planning.pipeline.target import (
    DEFAULT_TOLERANCE_M,
    DEFAULT_TOLERANCE_RAD,
    TOLERANCE_M_RANGE,
    TOLERANCE_RAD_RANGE,
    Target,
)
from planning.validation import unit_quaternion

JointValues = Annotated[list[Angle], Field(min_length=1, max_length=64)]
JointMap = Annotated[dict[Name, Angle], Field(min_length=1, max_length=64)]
Joints = Annotated[Annotated[JointValues, Tag(OTHER_TAG)] | Annotated[JointMap, Tag(MAPPING_TAG)], BY_KIND]


class PoseSpec(Strict):
    """``{xyz: [x, y, z], quat_xyzw: [x, y, z, w]}`` or ``{xyz, rpy: [roll, pitch, yaw]}``."""

    xyz: Point
    quat_xyzw: (
        Annotated[
            list[Annotated[float, Field(allow_inf_nan=False)]],
            Field(min_length=4, max_length=4),
            AfterValidator(lambda xyzw: list(unit_quaternion(xyzw))),
        ]
        | None
    ) = None
    rpy: Turn | None = None

    @model_validator(mode="after")
    def _one_orientation(self) -> Self:
        if (self.quat_xyzw is None) == (self.rpy is None):
            raise ValueError("give exactly one of 'quat_xyzw' [x, y, z, w] or 'rpy' [roll, pitch, yaw] [rad]")
        return self

    def rotation(self) -> np.ndarray:
        """The orientation as a rotation matrix."""
        if self.quat_xyzw is not None:
            x, y, z, w = self.quat_xyzw
            return np.asarray(pin.Quaternion(w, x, y, z).matrix())  # normalised (unit_quaternion)
        assert self.rpy is not None  # exactly one (validator)
        return np.asarray(pin.rpy.rpyToMatrix(*self.rpy))


class TargetSpec(Strict):
    """A start or goal: exactly one of ``q``, ``tcp`` and ``pose`` (module docstring)."""

    q: Joints | None = None
    tcp: Point | None = None
    pose: PoseSpec | None = None
    hold: JointMap | None = None
    tolerance_m: Annotated[float, between(*TOLERANCE_M_RANGE)] = DEFAULT_TOLERANCE_M
    tolerance_rad: Annotated[float, between(*TOLERANCE_RAD_RANGE)] = DEFAULT_TOLERANCE_RAD

    @model_validator(mode="before")
    @classmethod
    def _held_joint_by_name(cls, data: Any) -> Any:
        """A joint named beside ``tcp`` (``{tcp: [...], <joint>: 0.1}``): say where it goes."""
        if isinstance(data, dict) and "tcp" in data:
            strays = [key for key in data if key not in cls.model_fields]
            if strays:
                raise ValueError(
                    f"{strays} not key(s) of a start or goal ({sorted(cls.model_fields)}); joints held "
                    f"with 'tcp' go in 'hold', e.g. hold: {{{strays[0]}: 0.0}}"
                )
        return data

    @model_validator(mode="after")
    def _one_of(self) -> Self:
        given = [name for name in ("q", "tcp", "pose") if getattr(self, name) is not None]
        if len(given) != 1:
            raise ValueError(
                "give exactly one of 'q' (joint values), 'tcp' (x, y, z) [m] or 'pose' (xyz and rotation)"
            )
        if self.tcp is None and self.hold:
            raise ValueError("'hold' (joints held at values) goes with 'tcp'")
        return self

    def target(self) -> Target:
        """The :class:`~planning.pipeline.target.Target`."""
        tolerance_m, tolerance_rad = self.tolerance_m, self.tolerance_rad
        if self.q is not None:
            q = dict(self.q) if isinstance(self.q, dict) else tuple(self.q)
            return Target(q=q, tolerance_m=tolerance_m, tolerance_rad=tolerance_rad)
        if self.tcp is not None:
            return Target(
                tcp=(self.tcp[0], self.tcp[1], self.tcp[2]),
                hold=dict(self.hold or {}),
                tolerance_m=tolerance_m,
                tolerance_rad=tolerance_rad,
            )
        assert self.pose is not None  # exactly one (validator)
        rotation = tuple(tuple(row) for row in self.pose.rotation().tolist())
        pose = (tuple(self.pose.xyz), rotation)
        return Target(pose=pose, tolerance_m=tolerance_m, tolerance_rad=tolerance_rad)


def target_entry(target: Target) -> dict[str, Any]:
    """A start or goal in the scene file's form."""
    entry: dict[str, Any]
    if target.q is not None:
        q = target.q
        entry = {"q": {k: float(v) for k, v in q.items()} if isinstance(q, dict) else [float(v) for v in q]}
    elif target.tcp is not None:
        entry = {"tcp": [float(v) for v in target.tcp]}
        if target.hold:
            entry["hold"] = {name: float(value) for name, value in target.hold.items()}
    else:
        assert target.pose is not None  # exactly one (Target)
        position, rotation = target.pose
        q = pin.Quaternion(np.asarray(rotation)).normalized()
        entry = {"pose": {"xyz": [float(v) for v in position], "quat_xyzw": [q.x, q.y, q.z, q.w]}}
    if target.tolerance_m != DEFAULT_TOLERANCE_M:
        entry["tolerance_m"] = target.tolerance_m
    if target.tolerance_rad != DEFAULT_TOLERANCE_RAD:
        entry["tolerance_rad"] = target.tolerance_rad
    return entry
