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
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

import cpr_kin as ck
from cpr_kin.common.names import repeated
from cpr_kin.common.user_files import UserFileError, load_yaml
from cpr_kin.kinematics.dynamics import PAYLOAD_NAME
from planning.curves.spline_settings import SplineSettings
from planning.errors import PlanningError, SceneError
from planning.io.cloud_entry import PointCloudSpec, RobotAtStart, cloud_obstacles
from planning.io.publish import write_file
from planning.io.robot_entry import default_robot, robot_entry, robot_spec_of
from planning.io.scene_schema import (
    BoxSpec,
    CapsuleSpec,
    CylinderSpec,
    MeshSpec,
    SceneSpec,
    SphereSpec,
    describe_errors,
)
from planning.io.target_entry import target_entry
from planning.pipeline.scene import DEFAULT_SELF_MARGIN_M, MAX_OBSTACLES, Scene
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target

MAX_SCENE_BYTES = 1_000_000
"""Largest scene file [bytes]: the largest valid scene (500 obstacles) takes about 60 kB."""


def parse_scene(data: Any, source: str = "scene", base: Path | None = None) -> Scene:
    """Validate a scene given as parsed YAML and build the :class:`Scene`.

    Args:
        data: the parsed document (must be a mapping).
        source: name of the file for messages.
        base: folder that relative paths (robot, meshes) are resolved against (default: the
            current folder); the scene holds them as absolute paths.

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
        raise SceneError(f"{source}: {describe_errors(exc)}") from None
    base = base or Path.cwd()
    try:
        robot = robot_spec_of(spec.robot, base)
    except ck.CprKinError as exc:
        raise SceneError(f"{source}: robot: {exc}") from None
    try:
        payload = None
        if spec.payload is not None:
            shape = spec.payload.shape
            payload = spec.payload.payload(None if shape is None else _obstacle(shape, "payload", base))
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
                obstacles.append(_obstacle(item, name, base))
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
    try:
        return Scene(
            name=spec.name or source,
            robot=robot,
            safety_margin=spec.safety_margin,
            self_margin=spec.self_margin,
            allowed_collisions=tuple((a, b) for a, b in spec.allowed_collisions),
            start=start,
            goal=spec.goal.target(),
            duration=spec.duration,
            obstacles=tuple(obstacles),
            planner=PlannerSettings.from_flat(planner),
            spline=SplineSettings(p=spec.spline.p, a=tuple(spec.spline.a), ends=spec.spline.ends),  # type: ignore[arg-type]
            payload=payload,
            torque_scale=spec.torque_scale,
        )
    except PlanningError as exc:
        raise SceneError(f"{source}: {exc}") from None


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


def _obstacle(
    item: BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec, name: str, base: Path
) -> ck.Obstacle:
    """The obstacle (or payload shape) of a validated entry; a mesh relative to ``base``.

    Raises:
        cpr_kin.CprKinError: a shape coal cannot build, a mesh that cannot be read.
    """
    if isinstance(item, BoxSpec):
        return ck.Obstacle.box(item.size, item.xyz, item.rpy, name=name)
    if isinstance(item, SphereSpec):
        return ck.Obstacle.sphere(item.radius, item.xyz, name=name)
    if isinstance(item, CylinderSpec):
        return ck.Obstacle.cylinder(item.radius, item.length, item.xyz, item.rpy, name=name)
    if isinstance(item, CapsuleSpec):
        return ck.Obstacle.capsule(item.radius, item.length, item.xyz, item.rpy, name=name)
    mesh = (base / item.mesh).resolve()  # absolute: the scene may be planned elsewhere
    obstacle = ck.Obstacle.from_mesh(mesh, item.xyz, item.rpy, item.scale, item.convex, name=name)
    obstacle.geometry()  # read the file now: a broken mesh is a scene error
    return obstacle


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file; raises :class:`SceneError` naming what is wrong.

    The file is read by :func:`cpr_kin.common.user_files.load_yaml`: at most
    :data:`MAX_SCENE_BYTES`, no anchors or aliases, no duplicate keys, bounded nesting.
    """
    path = Path(path)
    try:
        data = load_yaml(path, MAX_SCENE_BYTES, "scene file")
    except UserFileError as exc:
        raise SceneError(str(exc)) from None
    return parse_scene(data, source=str(path), base=path.parent)


def obstacle_to_dict(obstacle: ck.Obstacle) -> dict[str, Any]:
    """An obstacle in the scene file's form (docs/formats.md)."""
    entry: dict[str, Any] = {"name": obstacle.name, "shape": obstacle.shape}
    if obstacle.shape == "box":
        entry["size"] = np.asarray(obstacle.size).tolist()
    if obstacle.shape in ("sphere", "cylinder", "capsule"):
        entry["radius"] = obstacle.radius
    if obstacle.shape in ("cylinder", "capsule"):
        entry["length"] = obstacle.length
    if obstacle.shape == "mesh":
        entry.update(mesh=str(obstacle.mesh), scale=obstacle.scale, convex=obstacle.convex)
    if obstacle.shape == "voxels":  # the voxel centres: they read back as the same voxels
        entry.update(
            shape="point_cloud", points=np.asarray(obstacle.points).tolist(), resolution=obstacle.resolution
        )
    entry.update(xyz=obstacle.xyz.tolist(), rpy=obstacle.rpy.tolist())
    return entry


def scene_to_dict(scene: Scene) -> dict[str, Any]:
    """The scene as planned: robot (unless the default), obstacles, margins, start, goal, duration."""
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
        "goal": target_entry(scene.goal),
        "duration": scene.duration,
        "obstacles": [obstacle_to_dict(o) for o in scene.obstacles],
        **({} if scene.payload is None else {"payload": payload_to_dict(scene.payload)}),
        **({} if scene.torque_scale == 1.0 else {"torque_scale": scene.torque_scale}),
    }


def payload_to_dict(payload: ck.Payload) -> dict[str, Any]:
    """A payload in the scene file's form (docs/formats.md)."""
    entry: dict[str, Any] = {} if payload.name == PAYLOAD_NAME else {"name": payload.name}
    entry |= {"mass_kg": payload.mass_kg, "com_in_tcp": list(payload.com_in_frame_m)}
    if payload.inertia_kg_m2 is not None:
        entry["inertia"] = [list(row) for row in payload.inertia_kg_m2]
    if payload.frame is not None:
        entry["frame"] = payload.frame
    if payload.shape is not None:
        entry["shape"] = {k: v for k, v in obstacle_to_dict(payload.shape).items() if k != "name"}
    if payload.touch_links:
        entry["touch_links"] = list(payload.touch_links)
    return entry


def scene_document(scene: Scene) -> dict[str, Any]:
    """The scene file's document for ``scene`` (the inverse of :func:`parse_scene`)."""
    planner = scene.planner.flat()
    if planner["moving_joints"] is not None:
        planner["moving_joints"] = list(planner["moving_joints"])
    document = scene_to_dict(scene)
    if document["duration"] is None:
        del document["duration"]
    document["planner"] = planner
    document["spline"] = {"p": scene.spline.p, "a": list(scene.spline.a), "ends": scene.spline.ends}
    return document


def dump_scene(scene: Scene, path: str | Path) -> None:
    """Write ``scene`` as a scene file, atomically."""
    write_file(Path(path), yaml.safe_dump(scene_document(scene), sort_keys=False, default_flow_style=None))
