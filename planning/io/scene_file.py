"""Scene files (YAML, DESIGN.md section 6): loading and validation.

Every key is checked against a schema (pydantic): unknown keys, wrong types, values out of
range and inconsistent combinations are reported as one :class:`SceneError` whose message
names the file, the field path (``obstacles[1].size[2]``), the value and what is allowed.

Defaults of the optional keys: ``robot``: the bundled CPR; ``safety_margin``: 0.1 m;
``duration``: none (the fastest uniform timing within the joint limits); ``obstacles``:
none; ``rpy``: ``[0, 0, 0]``; mesh ``scale``: 1 and ``convex``: true; ``planner``: the
paper's (50 fireflies, 50 iterations, alpha 1, beta0 0.5, gamma 1, theta 0.97, 3 waypoints,
sweep mode, clearance fitness, seed 0, spline path, IPO 0.012 s, 64 fitness samples,
verification step 0.005 m, no bound on the node deviation); ``spline``: p = 1e6,
a = [0, 0, 1], ``ends: rest``.
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

import cpr_kin as ck
from planning.curves.spline import SplineSettings
from planning.errors import PlanningError
from planning.scene import PlannerSettings, Scene, Target

# libyaml's safe loader where PyYAML was built with it: it parses a scene file about 7x faster
SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class SceneError(PlanningError):
    """A scene file is missing, not YAML, or does not follow the schema."""


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


_P = PlannerSettings  # the defaults are the settings' own


class PlannerSpec(_Strict):
    """The ``planner:`` block; see :class:`planning.scene.PlannerSettings` (same defaults)."""

    fireflies: Annotated[int, Field(ge=2)] = _P.fireflies
    iterations: Annotated[int, Field(ge=0)] = _P.iterations
    alpha: NonNegative = _P.alpha
    beta0: NonNegative = _P.beta0
    gamma: NonNegative = _P.gamma
    theta: Annotated[float, Field(gt=0, le=1)] = _P.theta
    waypoints: Annotated[int, Field(ge=1)] = _P.waypoints
    mode: Literal["sweep", "sequential"] = _P.mode
    fitness: Literal["clearance", "paper"] = _P.fitness
    seed: Annotated[int, Field(ge=0)] = _P.seed
    path: Literal["spline", "ptp"] = _P.path
    ipo: Positive = _P.ipo
    fitness_samples: Annotated[int, Field(ge=2)] = _P.fitness_samples
    verify_step_m: Positive = _P.verify_step_m
    max_node_deviation: Positive | None = _P.max_node_deviation
    moving_joints: list[Literal["theta1", "d2", "d3", "theta4", "theta5"]] | None = None


class SplineSpec(_Strict):
    """The ``spline:`` block; see :class:`planning.curves.spline.SplineSettings`."""

    p: Annotated[float, Field(gt=0)] = 1e6
    a: Annotated[list[NonNegative], Field(min_length=3, max_length=3)] = Field(
        default_factory=lambda: [0.0, 0.0, 1.0]
    )
    ends: Literal["natural", "rest"] = "rest"

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
    safety_margin: NonNegative = 0.1
    start: TargetSpec
    goal: TargetSpec
    duration: Positive | None = None
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    planner: PlannerSpec = Field(default_factory=PlannerSpec)
    spline: SplineSpec = Field(default_factory=SplineSpec)


_SHAPE_NAMES = ("box", "sphere", "cylinder", "capsule", "mesh")


def _path(location: tuple[int | str, ...]) -> str:
    text = ""
    for part in location:
        if isinstance(part, int):
            text += f"[{part}]"
        elif part in _SHAPE_NAMES:
            continue  # the discriminator's branch, not a key of the file
        else:
            text += f".{part}" if text else str(part)
    return text or "(top level)"


def _describe(error: dict[str, Any], model: type[BaseModel] | None) -> str:
    where = _path(tuple(error["loc"]))
    value = error.get("input")
    if error["type"] == "extra_forbidden":
        allowed = ", ".join(model.model_fields) if model is not None else ""
        return f"{where}: unknown key; allowed here: {allowed}"
    if error["type"] == "missing":
        return f"{where}: required key is missing"
    if error["type"] in ("union_tag_invalid", "union_tag_not_found") and isinstance(value, dict):
        allowed = ", ".join(_SHAPE_NAMES)
        return f"{where}.shape = {value.get('shape')!r}: unknown or missing shape; allowed: {allowed}"
    message = error["msg"].removeprefix("Value error, ")
    return f"{where} = {value!r}: {message}"


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


def _model_at(location: tuple[int | str, ...]) -> type[BaseModel] | None:
    """The schema model that owns the key at ``location`` (to list the allowed keys)."""
    if len(location) == 1:
        return SceneSpec
    if location[0] == "obstacles" and len(location) >= 4:
        return _SHAPE_SPECS.get(str(location[2]))
    return _BLOCK_SPECS.get(str(location[0]))


def parse_scene(data: Any, source: str = "scene", base: Path | None = None) -> Scene:
    """Validate a scene given as parsed YAML and build the :class:`Scene`.

    Args:
        data: the parsed document (must be a mapping).
        source: name of the file for messages.
        base: folder that relative paths (robot, meshes) are resolved against.

    Raises:
        SceneError: anything wrong, with the field path, the value and what is allowed.
    """
    if not isinstance(data, dict):
        raise SceneError(
            f"{source}: a scene must be a mapping of keys (start, goal, obstacles, ...), "
            f"not {type(data).__name__}"
        )
    try:
        spec = SceneSpec.model_validate(data)
    except ValidationError as exc:
        problems = [_describe(dict(e), _model_at(tuple(e["loc"]))) for e in exc.errors()]
        raise SceneError(f"{source}: " + "; ".join(problems)) from None
    base = base or Path.cwd()
    obstacles = []
    for index, item in enumerate(spec.obstacles):
        name = item.name or f"{item.shape}_{index}"
        try:
            if isinstance(item, BoxSpec):
                obstacles.append(ck.Obstacle.box(item.size, item.xyz, item.rpy, name=name))
            elif isinstance(item, SphereSpec):
                obstacles.append(ck.Obstacle.sphere(item.radius, item.xyz, name=name))
            elif isinstance(item, CylinderSpec):
                obstacles.append(
                    ck.Obstacle.cylinder(item.radius, item.length, item.xyz, item.rpy, name=name)
                )
            elif isinstance(item, CapsuleSpec):
                obstacles.append(ck.Obstacle.capsule(item.radius, item.length, item.xyz, item.rpy, name=name))
            else:
                mesh = Path(item.mesh) if Path(item.mesh).is_absolute() else base / item.mesh
                obstacle = ck.Obstacle.from_mesh(mesh, item.xyz, item.rpy, item.scale, item.convex, name=name)
                obstacle.geometry()  # read the file now: a broken mesh is a scene error
                obstacles.append(obstacle)
        except ck.CprKinError as exc:
            raise SceneError(f"{source}: obstacles[{index}]: {exc}") from None
    names = [o.name for o in obstacles]
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise SceneError(
            f"{source}: obstacles: names {duplicated} appear more than once; names must be unique"
        )
    planner = spec.planner.model_dump()
    if planner["moving_joints"] is not None:
        planner["moving_joints"] = tuple(planner["moving_joints"])
    robot = (
        None
        if spec.robot is None
        else (Path(spec.robot) if Path(spec.robot).is_absolute() else base / spec.robot)
    )
    try:
        return Scene(
            name=spec.name or source,
            robot=robot,
            safety_margin=spec.safety_margin,
            start=_target(spec.start),
            goal=_target(spec.goal),
            duration=spec.duration,
            obstacles=tuple(obstacles),
            planner=PlannerSettings(**planner),
            spline=SplineSettings(p=spec.spline.p, a=tuple(spec.spline.a), ends=spec.spline.ends),  # type: ignore[arg-type]
        )
    except PlanningError as exc:
        raise SceneError(f"{source}: {exc}") from None


def _target(spec: TargetSpec) -> Target:
    if spec.tcp is None:  # TargetSpec guarantees exactly one of tcp and q
        return Target(q=tuple(spec.q or ()))
    return Target(tcp=(spec.tcp[0], spec.tcp[1], spec.tcp[2]), theta4=spec.theta4, theta5=spec.theta5)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raises :class:`SceneError` naming what is wrong."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise SceneError(f"scene file '{path}' does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"cannot read scene file '{path}': {exc}") from None
    try:
        data = yaml.load(text, Loader=SAFE_LOADER)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or " ".join(str(exc).split())
        raise SceneError(f"scene file '{path}' is not valid YAML{where}: {problem}") from None
    return parse_scene(data, source=str(path), base=path.parent)


def paper_scene_path() -> Path:
    """The bundled paper scene, ``planning/scenes/paper.yaml``."""
    return Path(str(resources.files("planning") / "scenes" / "paper.yaml"))


def scene_document(scene: Scene) -> dict[str, Any]:
    """The scene file's document for ``scene`` (the inverse of :func:`parse_scene`)."""
    from dataclasses import asdict

    from planning.io.trajectory_io import obstacle_to_dict, target_to_dict

    planner = asdict(scene.planner)
    if planner["moving_joints"] is not None:
        planner["moving_joints"] = list(planner["moving_joints"])
    document: dict[str, Any] = {
        "name": scene.name,
        "safety_margin": scene.safety_margin,
        "start": target_to_dict(scene.start),
        "goal": target_to_dict(scene.goal),
        "obstacles": [obstacle_to_dict(o) for o in scene.obstacles],
        "planner": planner,
        "spline": {"p": scene.spline.p, "a": list(scene.spline.a), "ends": scene.spline.ends},
    }
    if scene.duration is not None:
        document["duration"] = scene.duration
    if scene.robot is not None:
        document["robot"] = str(scene.robot)
    return document


def dump_scene(scene: Scene, path: Path) -> None:
    """Write ``scene`` as a scene file, atomically."""
    from planning.io.trajectory_io import atomic_write_text

    atomic_write_text(
        Path(path), yaml.safe_dump(scene_document(scene), sort_keys=False, default_flow_style=None)
    )
