"""The scene file's schema (DESIGN.md section 6) as pydantic models, and its error messages.

Unknown keys are errors; every optional key has the default of the setting it fills
(:mod:`planning.scene`), so the file and the library cannot disagree. A validation error
becomes one line per problem naming the field path (``obstacles[1].size[2]``), the value
and what is allowed (:func:`describe_errors`).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from planning.scene import DEFAULT_SAFETY_MARGIN_M, DEFAULT_SPLINE, PlannerSettings
from planning.search.firefly import FireflySettings

Finite = Annotated[float, Field(allow_inf_nan=False)]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]
Vector3 = Annotated[list[Finite], Field(min_length=3, max_length=3)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class _Placed(_Strict):
    name: str | None = None
    xyz: Vector3
    rpy: Vector3 = Field(default_factory=lambda: [0.0, 0.0, 0.0])


class BoxSpec(_Placed):
    """``{shape: box, size: [x, y, z], xyz, rpy}``: full side lengths [m]."""

    shape: Literal["box"]
    size: Annotated[list[Positive], Field(min_length=3, max_length=3)]


class SphereSpec(_Placed):
    """``{shape: sphere, radius, xyz}`` [m]."""

    shape: Literal["sphere"]
    radius: Positive


class CylinderSpec(_Placed):
    """``{shape: cylinder, radius, length, xyz, rpy}``: axis along the local z [m]."""

    shape: Literal["cylinder"]
    radius: Positive
    length: Positive


class CapsuleSpec(_Placed):
    """``{shape: capsule, radius, length, xyz, rpy}``: segment along the local z [m]."""

    shape: Literal["capsule"]
    radius: Positive
    length: Positive


class MeshSpec(_Placed):
    """``{shape: mesh, mesh: FILE, scale, convex, xyz, rpy}``; FILE relative to the scene."""

    shape: Literal["mesh"]
    mesh: str
    scale: Positive = 1.0
    convex: bool = True


ObstacleSpec = Annotated[
    BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec, Field(discriminator="shape")
]


class TargetSpec(_Strict):
    """``{tcp: [x, y, z]}`` (with optional ``theta4``, ``theta5``) or ``{q: [5 joint values]}``."""

    tcp: Vector3 | None = None
    q: Annotated[list[Finite], Field(min_length=5, max_length=5)] | None = None
    theta4: Finite = 0.0
    theta5: Finite = 0.0

    @model_validator(mode="after")
    def _one_of(self) -> TargetSpec:
        if (self.tcp is None) == (self.q is None):
            raise ValueError(
                "give exactly one of 'tcp' (x, y, z) [m] or 'q' (theta1, d2, d3, theta4, theta5)"
            )
        if self.q is not None and (self.theta4 or self.theta5):
            raise ValueError("theta4 and theta5 go with 'tcp'; with 'q' they are part of the joint vector")
        return self


_F, _P = FireflySettings, PlannerSettings  # the defaults are the settings' own


class PlannerSpec(_Strict):
    """The flat ``planner:`` block; see :class:`~planning.scene.PlannerSettings` (same defaults)."""

    fireflies: Annotated[int, Field(ge=2)] = _F.fireflies
    iterations: Annotated[int, Field(ge=0)] = _F.iterations
    alpha: NonNegative = _F.alpha
    beta0: NonNegative = _F.beta0
    gamma: NonNegative = _F.gamma
    theta: Annotated[float, Field(gt=0, le=1)] = _F.theta
    mode: Literal["sweep", "sequential"] = _F.mode
    waypoints: Annotated[int, Field(ge=1)] = _P.waypoints
    fitness: Literal["clearance", "paper"] = _P.fitness
    seed: Annotated[int, Field(ge=0)] = _P.seed
    path: Literal["spline", "ptp"] = _P.path
    ipo: Positive = _P.ipo
    fitness_samples: Annotated[int, Field(ge=2)] = _P.fitness_samples
    verify_step_m: Positive = _P.verify_step_m
    max_node_deviation: Positive | None = _P.max_node_deviation
    moving_joints: list[Literal["theta1", "d2", "d3", "theta4", "theta5"]] | None = None


class SplineSpec(_Strict):
    """The ``spline:`` block; see :class:`~planning.curves.spline.SplineSettings`."""

    p: Annotated[float, Field(gt=0)] = float(DEFAULT_SPLINE.p)  # type: ignore[arg-type]
    a: Annotated[list[NonNegative], Field(min_length=3, max_length=3)] = Field(
        default_factory=lambda: list(DEFAULT_SPLINE.a)
    )
    ends: Literal["natural", "rest"] = DEFAULT_SPLINE.ends

    @model_validator(mode="after")
    def _some_weight(self) -> SplineSpec:
        if not any(self.a):
            raise ValueError(
                "a = [0, 0, 0] leaves the spline undetermined; give a weight > 0, e.g. a: [0, 0, 1]"
            )
        if math.isnan(self.p):
            raise ValueError("p must be a number > 0 (.inf interpolates exactly)")
        return self


class SceneSpec(_Strict):
    """A whole scene file."""

    name: str | None = None
    robot: str | None = None
    safety_margin: NonNegative = DEFAULT_SAFETY_MARGIN_M
    start: TargetSpec
    goal: TargetSpec
    duration: Positive | None = None
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    planner: PlannerSpec = Field(default_factory=PlannerSpec)
    spline: SplineSpec = Field(default_factory=SplineSpec)


_SHAPE_SPECS: dict[str, type[BaseModel]] = {
    "box": BoxSpec,
    "sphere": SphereSpec,
    "cylinder": CylinderSpec,
    "capsule": CapsuleSpec,
    "mesh": MeshSpec,
}
_BLOCK_SPECS: dict[str, type[BaseModel]] = {
    "start": TargetSpec,
    "goal": TargetSpec,
    "planner": PlannerSpec,
    "spline": SplineSpec,
}


def _path(location: tuple[int | str, ...]) -> str:
    text = ""
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
        elif part in _SHAPE_SPECS:
            continue  # the discriminator's branch, not a key of the file
        else:
            text += f".{part}" if text else str(part)
    return text or "(top level)"


def _model_at(location: tuple[int | str, ...]) -> type[BaseModel] | None:
    """The schema model that owns the key at ``location`` (to list the allowed keys)."""
    if len(location) == 1:
        return SceneSpec
    if location[0] == "obstacles" and len(location) >= 4:
        return _SHAPE_SPECS.get(str(location[2]))
    return _BLOCK_SPECS.get(str(location[0]))


def _describe(error: dict[str, Any]) -> str:
    location = tuple(error["loc"])
    where = _path(location)
    value = error.get("input")
    if error["type"] == "extra_forbidden":
        model = _model_at(location)
        allowed = ", ".join(model.model_fields) if model is not None else ""
        return f"{where}: unknown key; allowed here: {allowed}"
    if error["type"] == "missing":
        return f"{where}: required key is missing"
    if error["type"] in ("union_tag_invalid", "union_tag_not_found") and isinstance(value, dict):
        allowed = ", ".join(_SHAPE_SPECS)
        return f"{where}.shape = {value.get('shape')!r}: unknown or missing shape; allowed: {allowed}"
    message = error["msg"].removeprefix("Value error, ")
    return f"{where} = {value!r}: {message}"


def describe_errors(error: ValidationError) -> str:
    """One ``; ``-separated line naming every problem of a failed validation."""
    return "; ".join(_describe(dict(e)) for e in error.errors())
