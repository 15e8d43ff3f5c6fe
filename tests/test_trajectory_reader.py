from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.io.trajectory_io import trajectory_document
from planning.io.trajectory_reader import (
    MAX_TRAJECTORY_BYTES,
    TrajectoryFileError,
    parse_trajectory,
    read_trajectory,
)
from planning.pipeline.planner import plan


@pytest.fixture(scope="module")
def document(robot: ck.Robot) -> dict[str, Any]:
    return trajectory_document(plan(paper_scene(0), robot))


def changed(document: dict[str, Any], path: str, value: Any) -> bytes:
    """The document with ``path`` (e.g. ``segments.1.coeffs.0.3``) set to ``value``, as JSON."""
    new = copy.deepcopy(document)
    *parents, last = path.split(".")
    target: Any = new
    for key in parents:
        target = target[int(key)] if isinstance(target, list) else target[key]
    target[int(last) if isinstance(target, list) else last] = value
    return json.dumps(new).encode()


def test_a_written_file_reads_back_exactly(document: dict[str, Any]) -> None:
    read = parse_trajectory(json.dumps(document).encode())
    np.testing.assert_array_equal(read.trajectory.knots, document["knots"])
    np.testing.assert_array_equal(read.trajectory.coefficients[2], document["segments"][2]["coeffs"])
    assert read.joint_names == tuple(document["joint_names"]) and read.metrics == document["metrics"]
    assert read.certified_step_m == document["metrics"]["certified_step"] == 0.005  # the scene's step


@pytest.mark.parametrize("step", [0.0, -0.001, 0.5, 1e-9, "5 mm", True, [0.001]])
def test_a_recorded_step_check_could_not_take_is_refused(document: dict[str, Any], step: Any) -> None:
    """A step outside the settings' range (0.1 mm to 10 cm): ``check`` would run for hours on 1e-9 m."""
    with pytest.raises(TrajectoryFileError) as info:
        parse_trajectory(changed(document, "metrics.certified_step", step))
    assert f"metrics.certified_step = {step!r} is not a step in [0.0001, 0.1] m" in str(info.value)


def test_a_file_without_a_recorded_step_reads_with_none(document: dict[str, Any]) -> None:
    """A file written before the key (or by another tool) reads; ``check`` then tries the planner's steps."""
    older = copy.deepcopy(document)
    del older["metrics"]["certified_step"]
    assert parse_trajectory(json.dumps(older).encode()).certified_step_m is None
    assert parse_trajectory(changed(document, "metrics.certified_step", 0.0002)).certified_step_m == 0.0002


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        ("format", "other/2", "format = 'other/2': Input should be 'cpr-trajectory/1'"),
        (
            "segments.1.coeffs.0.3",
            float("nan"),
            "segments[1].coeffs[0][3] = nan: Input should be a finite number",
        ),
        ("segments.1.coeffs.0.3", True, "segments[1].coeffs[0][3] = True: Input should be a valid number"),
        ("segments.1.coeffs.0.7", 1e308, "segments[1].coeffs reach 1e+308; no joint moves beyond 1e+06"),
        ("segments.1.t0", 1.3, "segments[1].t0 = 1.3 s, but the knot there is 1.0 s"),
        ("segments.2.coeffs.4", [0.0] * 7, "segments[2].coeffs has rows of [8, 8, 8, 8, 7] values"),
        ("knots.2", 1.0, "knots[2] = 1.0 s must exceed knots[1] = 1.0 s"),
        ("knots", [0.0, 4.0], "4 segments for 2 knots"),
        ("waypoints.1", [0.0, 0.1], "waypoints[1] has 2 values; expected 5"),
        ("joint_names", "theta1", "joint_names = 'theta1': Input should be a valid array"),
    ],
)
def test_a_malformed_document_is_refused_naming_the_place(
    document: dict[str, Any], path: str, value: Any, message: str
) -> None:
    with pytest.raises(TrajectoryFileError) as info:
        parse_trajectory(changed(document, path, value))
    assert message in str(info.value) and len(str(info.value)) < 300


def test_long_values_in_many_places_keep_the_message_one_short_line(document: dict[str, Any]) -> None:
    """Hypothesis found it: three values of 36 characters once made a message of 300."""
    value = "0000\x1f\x1f\U00018cd6\U0001dab0"
    with pytest.raises(TrajectoryFileError) as info:
        parse_trajectory(changed(document, "segments.0.coeffs.1", [value] * 3))
    text = str(info.value)
    assert len(text) < 250 and "\n" not in text
    assert "segments[0].coeffs[1][0] = " in text and text.endswith("; and 1 more")


def test_a_missing_key_and_a_non_document() -> None:
    with pytest.raises(TrajectoryFileError, match=r"robot: required key is missing; .* and 1 more"):
        parse_trajectory(b'{"format": "cpr-trajectory/1", "joint_names": ["a"], "knots": [0, 1]}')
    with pytest.raises(TrajectoryFileError, match="is not valid JSON"):
        parse_trajectory(b"{not json")
    with pytest.raises(TrajectoryFileError, match=r"is not valid JSON: .*recursion"):
        parse_trajectory(b"[" * 100_000 + b"]" * 100_000)


def test_files_that_are_not_files(tmp_path: Path) -> None:
    with pytest.raises(TrajectoryFileError, match=r"missing\.json' does not exist"):
        read_trajectory(tmp_path / "missing.json")
    with pytest.raises(TrajectoryFileError, match="is not a regular file"):
        read_trajectory(tmp_path)
    with pytest.raises(TrajectoryFileError, match="is not a regular file"):
        read_trajectory("/dev/zero")
    big = tmp_path / "big.json"
    with big.open("wb") as stream:
        stream.truncate(MAX_TRAJECTORY_BYTES + 1)  # sparse: no disk needed
    with pytest.raises(TrajectoryFileError, match=f"is larger than {MAX_TRAJECTORY_BYTES} bytes"):
        read_trajectory(big)


JSON = st.recursive(
    st.none() | st.booleans() | st.floats(allow_nan=True) | st.integers() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=12,
)
PLACES = [
    "format",
    "knots",
    "knots.1",
    "segments",
    "segments.0",
    "segments.0.t1",
    "segments.0.coeffs",
    "segments.0.coeffs.1",
    "segments.0.coeffs.1.2",
    "joint_names",
    "waypoints",
    "waypoints.0",
    "scene",
]


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(place=st.sampled_from(PLACES), value=JSON)
def test_any_change_reads_or_raises_the_package_error(
    document: dict[str, Any], place: str, value: Any
) -> None:
    try:
        read = parse_trajectory(changed(document, place, value))
    except TrajectoryFileError as exc:
        assert len(str(exc)) < 300 and "\n" not in str(exc)
        return
    assert np.all(np.isfinite(read.trajectory.coefficients))  # what is accepted is a trajectory
