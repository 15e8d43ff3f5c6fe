"""The scene file's schema (docs/formats.md) as pydantic models, and its error messages.

Unknown keys are errors; every optional key has the default of the setting it fills
(:mod:`planning.pipeline.scene`), so the file and the library cannot disagree. A validation error
becomes one line per problem naming the field path (``obstacles[1].size[2]``), the value
and what is allowed (:func:`describe_errors`).
"""

import math
from typing import Annotated, Literal, Self

from pydantic import AfterValidator, BaseModel, Field, ValidationError, model_validator

from cpr_kin.kinematics.dynamics import TORQUE_SCALE_RANGE
from planning.io.cloud_entry import PointCloudSpec
from planning.io.robot_entry import RobotEntry, RobotMapping
from planning.io.schema_types import (
    UNION_TAGS,
    Name,
    Strict,
    between,
    empty_list,
    printable,
)
from planning.io.shape_entry import (
    BoxSpec,
    CapsuleSpec,
    CylinderSpec,
    MeshSpec,
    ObstacleSpec,
    PayloadSpec,
    SphereSpec,
)
from planning.io.target_entry import PoseSpec, TargetSpec
from planning.io.task_entry import TaskSpec, task_model_at
from planning.pipeline.scene import (
    DEFAULT_SAFETY_MARGIN_M,
    DEFAULT_SELF_MARGIN_M,
    DEFAULT_SPLINE,
    DURATION_RANGE_S,
    MAX_OBSTACLES,
    MAX_SAFETY_MARGIN_M,
    SPLINE_A_RANGE,
    SPLINE_P_RANGE,
)
from planning.pipeline.settings import (
    DEFAULT_FIREFLY,
    IPO_RANGE_S,
    MAX_FITNESS_SAMPLES,
    MAX_SEED,
    MAX_TIME_LIMIT_S,
    MAX_WAYPOINTS,
    VERIFY_STEP_RANGE_M,
    PlannerSettings,
)
from planning.search.firefly_settings import (
    MAX_FIREFLIES,
    MAX_GAMMA,
    MAX_ITERATIONS,
    MAX_STEP,
)
from planning.validation import describe_validation

_F, _P = DEFAULT_FIREFLY, PlannerSettings  # the defaults are the settings' own


class PlannerSpec(Strict):
    """The flat ``planner:`` block; see :class:`~planning.pipeline.settings.PlannerSettings`."""

    fireflies: Annotated[int, Field(ge=2, le=MAX_FIREFLIES)] = _F.fireflies
    iterations: Annotated[int, Field(ge=0, le=MAX_ITERATIONS)] = _F.iterations
    alpha: Annotated[float, between(0.0, MAX_STEP)] = _F.alpha
    beta0: Annotated[float, between(0.0, MAX_STEP)] = _F.beta0
    gamma: Annotated[float, between(0.0, MAX_GAMMA)] = _F.gamma
    theta: Annotated[float, Field(gt=0, le=1)] = _F.theta
    mode: Literal["sweep", "sequential"] = _F.mode
    stall_iterations: Annotated[int, Field(ge=0, le=MAX_ITERATIONS)] = _F.stall_iterations
    waypoints: Annotated[int, Field(ge=1, le=MAX_WAYPOINTS)] = _P.waypoints
    fitness: Literal["clearance", "paper"] = _P.fitness
    seed: Annotated[int, Field(ge=0, le=MAX_SEED)] = _P.seed
    path: Literal["spline", "ptp"] = _P.path
    ipo: Annotated[float, between(*IPO_RANGE_S)] = _P.ipo
    fitness_samples: Annotated[int, Field(ge=2, le=MAX_FITNESS_SAMPLES)] = _P.fitness_samples
    verify_step_m: Annotated[float, between(*VERIFY_STEP_RANGE_M)] = _P.verify_step_m
    self_verify_step_m: Annotated[float, between(*VERIFY_STEP_RANGE_M)] = _P.self_verify_step_m
    max_node_deviation: Annotated[float, Field(gt=0, le=1)] | None = _P.max_node_deviation
    moving_joints: Annotated[list[Name], Field(min_length=1, max_length=64)] | None = None
    seeding: Literal["paths", "none"] = _P.seeding
    refine: Literal["cma", "none"] = _P.refine
    refine_stall: Annotated[int, Field(ge=0, le=MAX_ITERATIONS)] = _P.refine_stall
    time_limit_s: Annotated[float, Field(gt=0, le=MAX_TIME_LIMIT_S)] | None = _P.time_limit_s


class SplineSpec(Strict):
    """The ``spline:`` block; see :class:`~planning.curves.spline.SplineSettings`."""

    p: Annotated[float, Field(ge=SPLINE_P_RANGE[0])] = float(DEFAULT_SPLINE.p)  # type: ignore[arg-type]
    a: Annotated[
        list[Annotated[float, between(0.0, SPLINE_A_RANGE[1])]], Field(min_length=3, max_length=3)
    ] = Field(default_factory=lambda: list(DEFAULT_SPLINE.a))
    ends: Literal["natural", "rest"] = DEFAULT_SPLINE.ends

    @model_validator(mode="after")
    def _some_weight(self) -> Self:
        if not any(self.a):
            raise ValueError(
                "a = [0, 0, 0] leaves the spline undetermined; give a weight > 0, e.g. a: [0, 0, 1]"
            )
        if math.isnan(self.p) or (math.isfinite(self.p) and self.p > SPLINE_P_RANGE[1]):
            low, high = SPLINE_P_RANGE
            raise ValueError(f"p = {self.p!r} must be in [{low:g}, {high:g}] or .inf (exact interpolation)")
        if any(0 < a < SPLINE_A_RANGE[0] for a in self.a):
            raise ValueError(f"a weight other than 0 must be at least {SPLINE_A_RANGE[0]:g}")
        return self


class SceneSpec(Strict):
    """A whole scene file."""

    name: Annotated[str, Field(min_length=1, max_length=200), AfterValidator(printable)] | None = None
    robot: RobotEntry | None = None
    safety_margin: Annotated[float, between(0.0, MAX_SAFETY_MARGIN_M)] = DEFAULT_SAFETY_MARGIN_M
    self_margin: Annotated[float, between(0.0, MAX_SAFETY_MARGIN_M)] = DEFAULT_SELF_MARGIN_M
    allowed_collisions: Annotated[
        list[Annotated[list[Name], Field(min_length=2, max_length=2)]], Field(max_length=10_000)
    ] = Field(default_factory=empty_list)
    start: TargetSpec
    goal: TargetSpec | None = None
    task: TaskSpec | None = None
    duration: Annotated[float, between(*DURATION_RANGE_S)] | None = None
    obstacles: Annotated[list[ObstacleSpec], Field(max_length=MAX_OBSTACLES)] = Field(
        default_factory=empty_list
    )
    planner: PlannerSpec = Field(default_factory=PlannerSpec)
    spline: SplineSpec = Field(default_factory=SplineSpec)
    payload: PayloadSpec | None = None
    torque_scale: Annotated[float, between(*TORQUE_SCALE_RANGE)] = 1.0

    @model_validator(mode="after")
    def _goal_or_task(self) -> Self:
        if (self.goal is None) == (self.task is None):
            raise ValueError(
                "give exactly one of 'goal' (where one motion goes) or 'task' (a list of segments: move, "
                "line, wait, attach, detach)"
            )
        if self.task is not None and self.duration is not None:
            raise ValueError(
                f"duration = {self.duration:g} s: a task times each of its motions as fast as the limits "
                "allow; leave the duration out"
            )
        return self


_SHAPE_SPECS: dict[str, type[BaseModel]] = {
    "box": BoxSpec,
    "sphere": SphereSpec,
    "cylinder": CylinderSpec,
    "capsule": CapsuleSpec,
    "mesh": MeshSpec,
    "point_cloud": PointCloudSpec,
}
_BLOCK_SPECS: dict[str, type[BaseModel]] = {
    "start": TargetSpec,
    "goal": TargetSpec,
    "planner": PlannerSpec,
    "spline": SplineSpec,
    "payload": PayloadSpec,
}


def _model_at(location: tuple[int | str, ...]) -> type[BaseModel] | None:
    """The schema model that owns the key at ``location`` (to list the allowed keys)."""
    if len(location) == 1:
        return SceneSpec
    if location[0] == "obstacles" and len(location) >= 4:
        return _SHAPE_SPECS.get(str(location[2]))
    if location[:2] == ("payload", "shape") and len(location) >= 4:
        return _SHAPE_SPECS.get(str(location[2]))
    if location[0] == "task" and len(location) >= 3:
        return task_model_at(location[1:])
    if location[0] == "robot":
        return RobotMapping
    if location[0] in ("start", "goal") and location[1] == "pose":
        return PoseSpec
    return _BLOCK_SPECS.get(str(location[0]))


def describe_errors(error: ValidationError) -> str:
    """One line naming the first problems of a failed scene validation (field path, value, rule)."""
    shapes = tuple(_SHAPE_SPECS)
    return describe_validation(error, _model_at, hidden=(*shapes, *UNION_TAGS), tag=("shape", shapes))
