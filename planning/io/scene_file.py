"""Scene files (YAML, docs/formats.md): loading, validation and writing.

Every key is checked against the schema (:mod:`planning.io.scene_schema`): unknown keys,
wrong types, values out of range and inconsistent combinations are reported as one
:class:`~planning.errors.SceneError` whose message names the file, the field path
(``obstacles[1].size[2]``), the value and what is allowed.

Defaults of the optional keys: ``robot``: the bundled CPR; ``safety_margin``: 0.1 m;
``self_margin``: 0.01 m (between the robot's own checked link pairs); ``allowed_collisions``:
none;
``duration``: none (the fastest timing within the joint limits); ``obstacles``: none;
``rpy``: ``[0, 0, 0]``; mesh ``scale``: 1 and ``convex``: true; ``planner``: the paper's
firefly with 30 fireflies, alpha 0.5 and an early stop (50 iterations, beta0 0.5, gamma 1,
theta 0.97, sweep mode, 4 stalled iterations), seeded with paths, its best refined by a
CMA-ES, 3 waypoints, clearance
fitness, seed 0, spline path, IPO 0.012 s, 64 fitness samples, verification step 0.005 m,
no bound on the node deviation; ``spline``: p = 1e6, a = [0, 0, 1],
``ends: rest``. They are read from :mod:`planning.pipeline.scene`, the one place they are set.

A scene file holds a ``goal`` (one motion, :func:`load_scene`) or a ``task`` (segments,
:mod:`planning.io.task_entry`; :func:`load_scene_file` reads both).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from pydantic import ValidationError

import cpr_kin as ck
from cpr_kin.common.names import repeated
from cpr_kin.common.user_files import UserFileError, dump_yaml, load_yaml
from planning.curves.spline_settings import SplineSettings
from planning.errors import PlanningError, SceneError
from planning.io.cloud_entry import PointCloudSpec, RobotAtStart, cloud_obstacles
from planning.io.file_formats import WRITTEN
from planning.io.publish import write_file
from planning.io.robot_entry import default_robot, robot_entry, robot_spec_of
from planning.io.scene_schema import SceneSpec, describe_errors
from planning.io.shape_entry import obstacle_of, obstacle_to_dict, payload_to_dict
from planning.io.target_entry import target_entry
from planning.pipeline.scene import DEFAULT_SELF_MARGIN_M, MAX_OBSTACLES, Scene
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target

if TYPE_CHECKING:
    from planning.task.segments import Segment

MAX_SCENE_BYTES = 1_000_000
"""Largest scene file [bytes]: the largest valid scene (500 obstacles) takes about 60 kB."""


@dataclass(frozen=True)
class SceneFile:
    """A scene file read: its scene, and its task if it holds one.

    Attributes:
        scene: the scene; where the file holds a task, its goal is its start (a task's
            segments say where the robot goes).
        task: the task's segments in order (:mod:`planning.task`); empty: the scene's one motion.
    """

    scene: Scene
    task: tuple[Segment, ...] = ()


def parse_scene(data: Any, source: str = "scene", base: Path | None = None) -> Scene:
    """Validate a scene given as parsed YAML and build the :class:`Scene` (not a task's: see below).

    Raises:
        SceneError: anything wrong, with the field path, the value and what is allowed; a
            scene that holds a task (:func:`parse_scene_file` reads it).
    """
    read = parse_scene_file(data, source, base)
    if read.task:
        raise SceneError(
            f"{source} holds a task of {len(read.task)} segments, not one motion to a goal: plan it with "
            "`cpr-plan plan`, or read it with planning.io.load_scene_file and plan it with "
            "planning.task.plan_task"
        )
    return read.scene


def parse_scene_file(data: Any, source: str = "scene", base: Path | None = None) -> SceneFile:
    """Validate a scene given as parsed YAML and build the :class:`SceneFile` (its scene and task).

    Args:
        data: the parsed document (must be a mapping).
        source: name of the file for messages.
        base: folder that relative paths (robot, meshes) are resolved against (default: the
            current folder); the scene holds them as absolute paths.

    Raises:
        SceneError: anything wrong, with the field path, the value and what is allowed.
    """
    spec = _validated(data, source)
    base = base or Path.cwd()
    robot = _robot_of(spec, base, source)
    try:
        payload = None
        if spec.payload is not None:
            shape = spec.payload.shape
            payload = spec.payload.payload(None if shape is None else obstacle_of(shape, "payload", base))
    except ck.CprKinError as exc:
        raise SceneError(f"{source}: payload: {exc}") from None
    start = spec.start.target()
    at_start = _robot_at_start(spec, robot, payload, start, source)
    obstacles: list[ck.Obstacle] = []
    for index, item in enumerate(spec.obstacles):
        try:
            name = item.name or f"{item.shape}_{index}"
            if isinstance(item, PointCloudSpec):
                obstacles += cloud_obstacles(item, name, base, at_start)
            else:
                obstacles.append(obstacle_of(item, name, base))
        except ck.CprKinError as exc:
            raise SceneError(f"{source}: obstacles[{index}]: {exc}") from None
    if len(obstacles) > MAX_OBSTACLES:  # a cloud's blocks count
        raise SceneError(
            f"{source}: obstacles: {len(obstacles)}, point clouds' blocks included; at most {MAX_OBSTACLES}: "
            "crop a point cloud to the robot's workspace, or give fewer obstacles"
        )
    names = [o.name for o in obstacles]
    duplicated = repeated(names)
    if duplicated:
        raise SceneError(
            f"{source}: obstacles: names {duplicated} appear more than once; names must be unique"
        )
    planner = spec.planner.model_dump()
    if planner["moving_joints"] is not None:
        planner["moving_joints"] = tuple(planner["moving_joints"])
    task: tuple[Segment, ...] = ()
    if spec.task is not None:
        from planning.io.task_segments import task_segments  # planning.task, where a scene has a task

        task = task_segments(spec.task, payload, base, source)
    try:
        scene = Scene(
            name=spec.name or source,
            robot=robot,
            safety_margin=spec.safety_margin,
            self_margin=spec.self_margin,
            allowed_collisions=tuple((a, b) for a, b in spec.allowed_collisions),
            start=start,
            goal=start if spec.goal is None else spec.goal.target(),
            duration=spec.duration,
            obstacles=tuple(obstacles),
            planner=PlannerSettings.from_flat(planner),
            spline=SplineSettings(p=spec.spline.p, a=tuple(spec.spline.a), ends=spec.spline.ends),  # type: ignore[arg-type]
            payload=payload,
            torque_scale=spec.torque_scale,
        )
    except PlanningError as exc:
        raise SceneError(f"{source}: {exc}") from None
    return SceneFile(scene, task)


def _robot_at_start(
    spec: SceneSpec, robot: ck.RobotSpec, payload: ck.Payload | None, start: Target, source: str
) -> RobotAtStart | None:
    """The robot at the start if a point cloud filters it out, else ``None`` (nothing loaded).

    Raises:
        SceneError: the start is not joint values, or not the robot's.
    """
    filtered = [i for i, o in enumerate(spec.obstacles) if isinstance(o, PointCloudSpec) and o.filter_robot]
    if not filtered:
        return None
    if start.q is None:
        given = "a tcp" if start.tcp is not None else "a pose"
        raise SceneError(
            f"{source}: obstacles[{filtered[0]}]: filter_robot needs the start as joint values "
            f"('start: {{q: [...]}}'), where the robot stands in the cloud; the start is {given}"
        )
    try:
        loaded = ck.carrying(robot.load(), payload)
    except ck.CprKinError as exc:
        raise SceneError(f"{source}: robot: {exc}") from None
    try:
        q = loaded.configuration(dict(start.q) if isinstance(start.q, Mapping) else start.q)
    except ck.CprKinError as exc:
        raise SceneError(f"{source}: start: {exc}") from None
    return RobotAtStart(loaded, q, spec.safety_margin)


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file of one motion; raises :class:`SceneError` naming what is wrong.

    The file is read by :func:`cpr_kin.common.user_files.load_yaml`: at most
    :data:`MAX_SCENE_BYTES`, no anchors or aliases, no duplicate keys, bounded nesting. A file
    that holds a task is refused (:func:`load_scene_file` reads it).
    """
    path = Path(path)
    return parse_scene(_read(path), source=str(path), base=path.parent)


def load_scene_file(path: str | Path) -> SceneFile:
    """Read and validate a scene file, a task's too (see :func:`load_scene`)."""
    path = Path(path)
    return parse_scene_file(_read(path), source=str(path), base=path.parent)


def scene_robot(path: str | Path) -> ck.RobotSpec:
    """The robot a scene file names (its ``robot:``; none: the CPR preset), the file checked as a scene's.

    What ``cpr-plan robot-info SCENE`` loads: the robot alone, not the obstacles or the ends.
    """
    path = Path(path)
    return _robot_of(_validated(_read(path), str(path)), path.parent, str(path))


def _validated(data: Any, source: str) -> SceneSpec:
    """The parsed document ``data`` checked by the scene schema (:class:`SceneError` naming what is wrong)."""
    if not isinstance(data, dict):
        raise SceneError(
            f"{source}: a scene must be a mapping of keys (start, goal, obstacles, ...), "
            f"not {type(data).__name__}"
        )
    written = data.get("format")
    if isinstance(written, str) and written in WRITTEN:  # the files of a command taken in the wrong order
        raise SceneError(
            f"{source} is {WRITTEN[written]} ({written}), not a scene; give the scene file "
            "(start, goal, obstacles) here, and that file where it is asked for"
        )
    try:
        return SceneSpec.model_validate(data)
    except ValidationError as exc:
        raise SceneError(f"{source}: {describe_errors(exc)}") from None


def _robot_of(spec: SceneSpec, base: Path, source: str) -> ck.RobotSpec:
    """The robot ``spec`` names, its paths relative to ``base``; its URDF a file (read when it loads)."""
    try:
        return robot_spec_of(spec.robot, base)
    except ck.CprKinError as exc:
        raise SceneError(f"{source}: robot: {exc}") from None


def _read(path: Path) -> Any:
    try:
        return load_yaml(path, MAX_SCENE_BYTES, "scene file")
    except UserFileError as exc:
        raise SceneError(str(exc)) from None


def scene_to_dict(scene: Scene, task: Sequence[Segment] = ()) -> dict[str, Any]:
    """The scene as planned: robot (unless the default), obstacles, margins, start, goal or task, duration."""
    return {
        "name": scene.name,
        **({} if scene.robot in (None, default_robot()) else {"robot": robot_entry(scene.robot)}),
        "safety_margin": scene.safety_margin,
        **({} if scene.self_margin == DEFAULT_SELF_MARGIN_M else {"self_margin": scene.self_margin}),
        **(
            {"allowed_collisions": [list(p) for p in scene.allowed_collisions]}
            if scene.allowed_collisions
            else {}
        ),
        "start": target_entry(scene.start),
        **({"task": _task_entries(task)} if task else {"goal": target_entry(scene.goal)}),
        "duration": scene.duration,
        "obstacles": [obstacle_to_dict(o) for o in scene.obstacles],
        **({} if scene.payload is None else {"payload": payload_to_dict(scene.payload)}),
        **({} if scene.torque_scale == 1.0 else {"torque_scale": scene.torque_scale}),
    }


def scene_document(scene: Scene, task: Sequence[Segment] = ()) -> dict[str, Any]:
    """The scene file's document for ``scene`` and its ``task`` (the inverse of :func:`parse_scene_file`)."""
    planner = scene.planner.flat()
    if planner["moving_joints"] is not None:
        planner["moving_joints"] = list(planner["moving_joints"])
    document = scene_to_dict(scene, task)
    if document["duration"] is None:
        del document["duration"]
    document["planner"] = planner
    document["spline"] = {"p": scene.spline.p, "a": list(scene.spline.a), "ends": scene.spline.ends}
    return document


def dump_scene(scene: Scene, path: str | Path) -> None:
    """Write ``scene`` as a scene file, atomically."""
    write_file(Path(path), dump_yaml(scene_document(scene)))


def _task_entries(task: Sequence[Segment]) -> list[dict[str, Any]]:
    """``task:`` in the scene file's form (:func:`planning.io.task_segments.task_entries`)."""
    from planning.io.task_segments import task_entries

    return task_entries(task)
