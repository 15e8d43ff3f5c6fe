from __future__ import annotations

import contextlib
import dataclasses
import json
import math
import re
from pathlib import Path
from typing import Any

import pytest
import trimesh
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import BaseModel

import cpr_kin as ck
from cpr_kin.common.user_files import StrictLoader, UserFileError, dump_yaml, load_yaml
from planning.bench.scene_generator import generate_scenes
from planning.curves.spline_settings import SplineSettings
from planning.errors import PlanningError, SceneError
from planning.io.bundled import bundled_scene_paths, duration_free_scenes, paper_scene, paper_scene_path
from planning.io.file_formats import OUTPUTS, TRAJECTORY
from planning.io.scene_file import (
    dump_scene,
    load_scene,
    parse_scene,
)
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.target import Target

MINIMAL = {"start": {"tcp": [0.5, 0.45, 0.25]}, "goal": {"tcp": [-0.5, 0.45, 0.25]}}


def test_bundled_paper_scene_is_the_paper_case_of_the_design() -> None:
    # docs/paper_case.md, value by value
    scene = paper_scene()
    assert scene.name == "paper" and scene.safety_margin == 0.1 and scene.duration == 4.0
    assert scene.start == Target(tcp=(0.5, 0.45, 0.25)) and scene.goal == Target(tcp=(-0.5, 0.45, 0.25))
    assert scene.obstacles == (ck.Obstacle.box((0.3, 0.3, 0.3), (0.0, 0.6, 0.15), name="crate"),)
    firefly = scene.planner.firefly
    assert (firefly.fireflies, firefly.alpha, firefly.beta0, firefly.iterations) == (50, 1.0, 0.5, 50)
    assert scene.planner.waypoints == 3 and scene.planner.max_node_deviation == 20e-6
    assert scene.spline == SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="natural")
    # the planner changes and the seed apply on top of the file, which holds seed 0
    assert load_scene(paper_scene_path()) == paper_scene(0)
    assert paper_scene(3, fireflies=10).planner == scene.planner.updated(seed=3, fireflies=10)


def test_documented_defaults() -> None:
    scene = parse_scene(MINIMAL)
    assert scene.safety_margin == 0.1
    assert scene.duration is None and scene.obstacles == ()
    assert scene.robot == ck.cpr_spec()  # no robot: the CPR preset, chosen where the file is read
    assert scene.planner == PlannerSettings()
    assert scene.spline == SplineSettings(p=1e6, a=(0.0, 0.0, 1.0), ends="rest")
    assert parse_scene({**MINIMAL, "planner": {"refine_stall": 0}}).planner.refine_stall == 0


def test_every_shape_and_relative_mesh_path(tmp_path: Path) -> None:
    trimesh.creation.box(extents=(0.1, 0.1, 0.1)).export(tmp_path / "part.stl")
    (tmp_path / "scene.yaml").write_text(
        yaml.safe_dump(
            {
                **MINIMAL,
                "obstacles": [
                    {"shape": "box", "size": [0.1, 0.2, 0.3], "xyz": [1, 1, 1]},
                    {"shape": "sphere", "radius": 0.1, "xyz": [1, -1, 1]},
                    {"shape": "cylinder", "radius": 0.1, "length": 0.5, "xyz": [-1, -1, 1], "rpy": [0, 1, 0]},
                    {"shape": "capsule", "radius": 0.1, "length": 0.5, "xyz": [-1, 1, 1]},
                    {"name": "part", "shape": "mesh", "mesh": "part.stl", "scale": 2.0, "xyz": [1, 0, 1.5]},
                ],
            }
        )
    )
    scene = load_scene(tmp_path / "scene.yaml")
    assert [o.shape for o in scene.obstacles] == ["box", "sphere", "cylinder", "capsule", "mesh"]
    assert [o.name for o in scene.obstacles][:2] == ["box_0", "sphere_1"]
    assert scene.obstacles[4].mesh == tmp_path / "part.stl"
    ck.CollisionWorld(ck.load_cpr(), scene.obstacles)  # every shape builds a coal geometry


def test_an_obstacles_touch_links_are_read_written_and_read_back_the_same(tmp_path: Path) -> None:
    fingers = ["tool_link", "wrist_link"]
    obstacles = [
        {
            "name": "part",
            "shape": "box",
            "size": [0.04, 0.04, 0.04],
            "xyz": [0.5, 0, 0.2],
            "touch_links": fingers,
        },
        {"name": "cap", "shape": "sphere", "radius": 0.02, "xyz": [0.5, 0, 0.3], "touch_links": fingers},
    ]
    scene = parse_scene({**MINIMAL, "obstacles": obstacles}, source="s.yaml")
    assert [o.touch_links for o in scene.obstacles] == [("tool_link", "wrist_link")] * 2
    dump_scene(scene, tmp_path / "again.yaml")
    assert load_scene(tmp_path / "again.yaml").obstacles == scene.obstacles
    shape = {"shape": "box", "size": [0.04, 0.04, 0.04], "xyz": [0, 0, 0.03], "touch_links": fingers}
    with pytest.raises(SceneError, match="not its shape's"):
        parse_scene({**MINIMAL, "payload": {"mass_kg": 1.0, "shape": shape}}, source="s.yaml")


@pytest.mark.parametrize(
    ("change", "pattern"),
    [
        ({"safety_margn": 0.1}, "safety_margn: unknown key; allowed here: name, robot, safety_margin"),
        (
            {"obstacles": [{"shape": "box", "size": [0.1, 0.1], "xyz": [0, 0, 0]}]},
            "obstacles[0].size: 2 items; needs at least 3",
        ),
        (
            {"obstacles": [{"shape": "sphere", "radius": 0.01, "xyz": [0, 0, 3 + k]} for k in range(501)]},
            "obstacles: 501 items; at most 500 allowed",  # the count, not the list
        ),
        (
            {"obstacles": [{"shape": "box", "size": [0.1, 0.1, 0.1]}]},
            "obstacles[0].xyz: required key is missing",
        ),
        (  # the key spelt like its shape's tag is named, not dropped with the tag
            {"obstacles": [{"shape": "mesh", "xyz": [0, 0, 0]}]},
            "obstacles[0].mesh: required key is missing",
        ),
        (
            {"payload": {"shape": {"shape": "mesh", "xyz": [0, 0, 0]}}},
            "payload.shape.mesh: required key is missing",
        ),
        (
            {"start": {"tcp": [0.5, 0.45, 0.25], "q": [0, 0, 0, 0, 0]}},
            "start: give exactly one of 'q' (joint values), 'tcp'",
        ),
        (
            {"goal": {"q": [0, 0, 0, 0, 0], "hold": {"theta4": 1.0}}},
            "'hold' (joints held at values) goes with 'tcp'",
        ),
        (
            {"goal": {"tcp": [0.5, 0.45, 0.25], "theta4": 1.0}},
            "['theta4'] not key(s) of a start or goal",
        ),
        ({"planner": {"mode": "parallel"}}, "planner.mode = 'parallel'"),
        ({"planner": {"refine": "bfgs"}}, "planner.refine = 'bfgs'"),
        ({"planner": {"refine_stall": -1}}, "planner.refine_stall = -1"),
        ({"spline": {"ends": "clamped"}}, "spline.ends = 'clamped'"),
        ({"duration": 0}, "duration = 0: Input should be greater than or equal to 0.01"),
        (
            {"obstacles": [{"name": "a", "shape": "sphere", "radius": 1, "xyz": [0, 0, 3]}] * 2},
            "names ['a'] appear more than once",
        ),
        (
            {"obstacles": [{"shape": "mesh", "mesh": "none.stl", "xyz": [0, 0, 0]}]},
            "obstacles[0]: obstacle 'mesh_0': mesh file",
        ),
    ],
)
def test_schema_errors_name_path_and_value(change: dict[str, Any], pattern: str) -> None:
    with pytest.raises(SceneError) as info:
        parse_scene({**MINIMAL, **change}, source="s.yaml")
    assert pattern in str(info.value)
    assert str(info.value).startswith("s.yaml: ")


def test_a_robot_urdf_that_is_no_file_is_named_with_the_scene(tmp_path: Path) -> None:
    # the scene read, the plan then said only "URDF file '.../nope.urdf' does not exist"
    with pytest.raises(SceneError, match=r"^s\.yaml: robot: URDF file '.*nope\.urdf' does not exist"):
        parse_scene({**MINIMAL, "robot": "nope.urdf"}, source="s.yaml", base=tmp_path)
    with pytest.raises(SceneError, match=r"^s\.yaml: robot: URDF file '.*' is not a regular file"):
        parse_scene({**MINIMAL, "robot": {"urdf": "."}}, source="s.yaml", base=tmp_path)


def test_file_errors(tmp_path: Path) -> None:
    with pytest.raises(SceneError, match=r"missing\.yaml' does not exist"):
        load_scene(tmp_path / "missing.yaml")
    (tmp_path / "broken.yaml").write_text("start: {tcp: [0.5, 0.45\n")
    with pytest.raises(SceneError, match="is not valid YAML"):
        load_scene(tmp_path / "broken.yaml")
    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    with pytest.raises(SceneError, match=r"must be a mapping of keys .* not list"):
        load_scene(tmp_path / "list.yaml")
    for name, written in (("trajectory", TRAJECTORY), ("manifest", OUTPUTS)):  # a plan's files, not scenes
        (tmp_path / f"{name}.json").write_text(json.dumps({"format": written, "sha256": {}}))
        with pytest.raises(SceneError, match=rf"{name}\.json is (a|an) .* \({written}\), not a scene"):
            load_scene(tmp_path / f"{name}.json")


# --- property tests: any input loads or raises SceneError, never anything else ---------------

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(-(10**6), 10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
)
values = st.recursive(
    scalars,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-5, 5), st.text(max_size=3), st.none()
)
vectors = st.lists(numbers, min_size=0, max_size=6)
obstacles = st.fixed_dictionaries(
    {"shape": st.sampled_from(["box", "sphere", "cylinder", "capsule", "mesh", "cone", 3])},
    optional={
        "size": vectors,
        "radius": numbers,
        "length": numbers,
        "xyz": vectors,
        "rpy": vectors,
        "name": st.text(max_size=4),
        "mesh": st.text(max_size=4),
        "extra": values,
    },
)
targets = st.one_of(
    st.fixed_dictionaries(
        {},
        optional={
            "tcp": vectors,
            "q": vectors,
            "hold": st.dictionaries(st.sampled_from(["theta4", "d2", "x"]), numbers),
        },
    ),
    values,
)
scenes = st.fixed_dictionaries(
    {"start": targets, "goal": targets},
    optional={
        "safety_margin": numbers,
        "duration": numbers,
        "obstacles": st.lists(obstacles, max_size=3),
        "planner": st.dictionaries(
            st.sampled_from(
                ["fireflies", "iterations", "alpha", "theta", "mode", "seed", "waypoints", "fitness", "typo"]
            ),
            numbers,
            max_size=4,
        ),
        "spline": st.dictionaries(
            st.sampled_from(["p", "a", "ends", "typo"]), st.one_of(numbers, vectors), max_size=3
        ),
        "robot": st.one_of(st.text(max_size=5), numbers),
    },
)


def _loads_or_scene_error(document: Any) -> None:
    try:
        parse_scene(document)
    except SceneError as exc:
        assert str(exc)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scenes)
def test_structured_inputs_load_or_raise_scene_error(document: dict[str, Any]) -> None:
    _loads_or_scene_error(document)


@settings(max_examples=300, deadline=None)
@given(values)
def test_arbitrary_inputs_load_or_raise_scene_error(document: Any) -> None:
    _loads_or_scene_error(document)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=60))
def test_arbitrary_text_files_load_or_raise_scene_error(
    tmp_path_factory: pytest.TempPathFactory, text: str
) -> None:
    path = tmp_path_factory.mktemp("scene") / "scene.yaml"
    path.write_text(text, encoding="utf-8")
    with contextlib.suppress(SceneError):  # anything but a SceneError fails the test
        load_scene(path)


def test_valid_scene_loads_with_finite_values() -> None:
    scene = parse_scene({**MINIMAL, "safety_margin": 0.05, "duration": 3.0})
    assert math.isclose(scene.safety_margin, 0.05) and scene.duration == 3.0


def test_bundled_example_scene_loads() -> None:
    scene = load_scene(paper_scene_path().parent / "shelf.yaml")
    assert sorted(o.shape for o in scene.obstacles) == ["box", "cylinder", "sphere"]


def test_duration_free_scenes_are_every_bundled_one_the_paper_freed() -> None:
    scenes = duration_free_scenes()
    assert len(scenes) == len(bundled_scene_paths())
    assert all(scene.duration is None for scene in scenes)
    freed = scenes[-1]
    assert freed.name == "paper_free" and freed.obstacles == paper_scene().obstacles
    assert paper_scene().duration == 4.0


def yaml12_floats(document: Any) -> Any:
    """``document`` with the strings PyYAML's YAML 1.1 resolver leaves as text (1.0e6) as floats."""
    if isinstance(document, dict):
        return {k: yaml12_floats(v) for k, v in document.items()}
    if isinstance(document, list):
        return [yaml12_floats(v) for v in document]
    if isinstance(document, str) and re.fullmatch(r"[-+]?[0-9][0-9_]*(\.[0-9_]*)?[eE][-+]?[0-9]+", document):
        return float(document)
    return document


def test_strict_loader_reads_scene_files_as_pyyaml_does(tmp_path: Path) -> None:
    """The strict loader (libyaml's parser) gives the documents of PyYAML's pure-Python safe loader.

    Except for one intended difference: ``1.0e6`` is a float (YAML 1.2), where PyYAML's
    YAML 1.1 resolver leaves it a string (which the strict schema would refuse).
    """
    assert issubclass(StrictLoader, yaml.CSafeLoader)  # the wheels ship libyaml; else the test is moot
    paths = sorted(paper_scene_path().parent.glob("*.yaml"))
    for scene in generate_scenes(5, seed=3):
        paths.append(tmp_path / f"{scene.name}.yaml")
        dump_scene(scene, paths[-1])
    for path in paths:
        text = path.read_text(encoding="utf-8")
        expected = yaml12_floats(yaml.load(text, Loader=yaml.SafeLoader))
        assert yaml.load(text, Loader=StrictLoader) == expected, path.name


yaml_pieces = st.lists(
    st.sampled_from(
        [
            "start: ",
            "goal: ",
            "{tcp: [0.5, 0.45, 0.25]}",
            "&a ",
            "*a",
            "[",
            "]",
            "{",
            "}",
            ", ",
            "\n",
            "  ",
            "obstacles: ",
            "- ",
            "1e6",
            "true",
            "'x'",
            "? ",
            ": ",
            "!!float ",
            "<<: *a",
            "---\n",
            "\t",
            "#",
        ]
    ),
    max_size=30,
)


@settings(max_examples=300, deadline=None)
@given(st.one_of(st.binary(max_size=120), yaml_pieces.map(lambda pieces: "".join(pieces).encode())))
def test_arbitrary_bytes_and_yaml_features_load_or_raise_one_short_scene_error(
    tmp_path_factory: pytest.TempPathFactory, data: bytes
) -> None:
    path = tmp_path_factory.mktemp("scene") / "scene.yaml"
    path.write_bytes(data)
    try:
        load_scene(path)
    except SceneError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 300 + len(str(path))


def test_with_planner_changes_the_settings_named_and_nothing_else() -> None:
    scene = paper_scene()
    changed = scene.with_planner(seed=7, fireflies=12)
    assert (changed.planner.seed, changed.planner.firefly.fireflies) == (7, 12)
    assert changed.planner == scene.planner.updated(seed=7, fireflies=12)
    assert dataclasses.replace(changed, planner=scene.planner) == scene
    with pytest.raises(PlanningError, match="fireflies"):
        scene.with_planner(fireflies=0)


def test_what_the_writers_dump_the_reader_takes_however_often_a_value_is_shared(tmp_path: Path) -> None:
    links = ["tool_link", "wrist_link"]  # one list in two places: PyYAML's safe_dump writes &id001 / *id001
    document = {"a": {"touch_links": links}, "b": {"touch_links": links}, "xyz": [0.1, 0.2, 0.3]}
    text = dump_yaml(document)
    assert "&" not in text and "*" not in text
    (tmp_path / "shared.yaml").write_text(text)
    assert load_yaml(tmp_path / "shared.yaml", 10_000) == document
    assert "xyz: [0.1, 0.2, 0.3]" in text  # scalars' lists in flow style, as before
    (tmp_path / "aliased.yaml").write_text(yaml.safe_dump(document))
    with pytest.raises(UserFileError, match="anchors"):  # what the reader refuses: the writer must not
        load_yaml(tmp_path / "aliased.yaml", 10_000)


def schema_models() -> set[type[BaseModel]]:
    """The pydantic models of the scene file's schema modules."""
    import inspect

    from planning.io import (
        cloud_entry,
        robot_entry,
        scene_schema,
        schema_types,
        shape_entry,
        target_entry,
        task_entry,
    )

    modules = (cloud_entry, robot_entry, scene_schema, schema_types, shape_entry, target_entry, task_entry)
    models = {
        model
        for module in modules
        for _, model in inspect.getmembers(module, inspect.isclass)
        if issubclass(model, BaseModel) and model.__module__ == module.__name__
    }
    assert len(models) >= 20
    return models


def test_the_schema_models_are_given_their_annotations_as_objects() -> None:
    # pydantic evaluates an annotation given as text (`from __future__ import annotations`)
    # for each field of each model in every process: half the time of making the models
    # (docs/tuning.md, One BLAS thread from the start); the schema's modules give it objects
    given_as_text = {
        f"{model.__name__}.{name}"
        for model in schema_models()
        for name, annotation in vars(model).get("__annotations__", {}).items()
        if isinstance(annotation, str)
    }
    assert given_as_text == set()


def test_no_schema_default_is_made_by_a_builtin_whose_signature_python_parses() -> None:
    # pydantic reads each default factory's signature; the builtin list's is text that
    # Python parses with tokenize, whose pattern a new process then compiles
    from planning.io.schema_types import empty_list

    factories = {
        f"{model.__name__}.{name}": field.default_factory
        for model in schema_models()
        for name, field in model.model_fields.items()
        if field.default_factory is not None
    }
    assert empty_list in factories.values()
    assert {name for name, made_by in factories.items() if made_by in (list, set, tuple, frozenset)} == set()
    assert empty_list() == [] and empty_list() is not empty_list()
