from __future__ import annotations

import json
import math

import numpy as np
import pytest

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.io.json_layout import dumps
from planning.io.trajectory_io import trajectory_document, trajectory_json
from planning.pipeline.planner import plan

from .conftest import strict_loads


def random_document(rng: np.random.Generator, depth: int = 0) -> object:
    """A seeded random JSON document: nested objects and lists of every JSON type."""
    kind = rng.integers(7 if depth < 4 else 4)
    if kind == 0:
        return float(rng.normal() * 10.0 ** rng.integers(-12, 12))
    if kind == 1:
        return int(rng.integers(-(10**12), 10**12))
    if kind == 2:
        return [None, True, False, "", 'quote " and \\ and \u00e9'][int(rng.integers(5))]
    if kind == 3:
        return rng.normal(size=int(rng.integers(0, 6))).tolist()
    if kind in (4, 5):
        return {f"k{i}": random_document(rng, depth + 1) for i in range(int(rng.integers(0, 4)))}
    return [random_document(rng, depth + 1) for _ in range(int(rng.integers(0, 4)))]


@pytest.mark.parametrize("seed", range(20))
def test_the_text_parses_to_the_document_json_writes(seed: int) -> None:
    document = {"root": random_document(np.random.default_rng(seed))}
    text = dumps(document)
    assert json.loads(text) == json.loads(json.dumps(document, indent=1))
    assert text == dumps(json.loads(text))  # floats survive the round trip digit for digit


def test_nested_containers_are_indented_and_flat_lists_take_one_line() -> None:
    document = {"name": "a", "empty": {}, "rows": [[1.0, 2.5], [3, 4]], "items": [{"x": []}], "v": [1, 2]}
    assert dumps(document, indent=2) == (
        "{\n"
        '  "name": "a",\n'
        '  "empty": {},\n'
        '  "rows": [\n'
        "    [1.0, 2.5],\n"
        "    [3, 4]\n"
        "  ],\n"
        '  "items": [\n'
        "    {\n"
        '      "x": []\n'
        "    }\n"
        "  ],\n"
        '  "v": [1, 2]\n'
        "}"
    )


def test_values_json_cannot_hold_are_refused_as_json_refuses_them() -> None:
    with pytest.raises(TypeError, match="not JSON serializable"):
        dumps({"a": [object()]})
    with pytest.raises(TypeError, match="keys must be strings, not int 3"):
        dumps({"a": {3: 1.0}})


def test_numbers_that_are_not_finite_are_written_null() -> None:
    document = {
        "a": math.inf,
        "b": [1.0, math.nan, -math.inf],
        "c": {"d": [[2, np.float64(np.inf)]]},
        "e": 2.5,
    }
    text = dumps(document)
    assert strict_loads(text) == {"a": None, "b": [1.0, None, None], "c": {"d": [[2, None]]}, "e": 2.5}
    with pytest.raises(ValueError, match="Infinity is not JSON"):
        strict_loads(json.dumps(document))  # what json writes: a strict parser refuses it


def test_a_trajectory_file_has_a_line_per_coefficient_row(robot: ck.Robot) -> None:
    result = plan(paper_scene(0), robot)
    document = trajectory_document(result)
    text = trajectory_json(result)
    assert json.loads(text) == json.loads(json.dumps(document))
    lines = {line.strip().rstrip(",") for line in text.splitlines()}
    for segment in document["segments"]:
        for row in segment["coeffs"]:
            assert json.dumps(row) in lines
    for waypoint in document["waypoints"]:
        assert json.dumps(waypoint) in lines
