"""Hostile and careless input: one short line, the right exit code, nothing written, no hang.

Every case runs through ``cpr-plan`` as a user meets it. Each asserts the exit code, one line
on stderr under 400 characters (the test's folder apart) that names the field, no traceback,
no output folder, and that the refusal comes before any search starts (the unguarded code
searched for minutes; ``scripts/bench_hostile.py`` prints the actual times).
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from planning.cli import main

GOOD = "start: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [-0.5, 0.45, 0.25]}\n"
CRATE = "obstacles:\n  - {name: crate, shape: box, size: [0.3, 0.3, 0.3], xyz: [0.0, 0.6, 0.15]}\n"
BOMB = (  # 9 levels of 9 aliases: 9^9 = 387 million strings once expanded
    'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
    + "".join(
        f"{n}: &{n} [*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p},*{p}]\n"
        for p, n in zip("abcdefgh", "bcdefghi", strict=True)
    )
    + GOOD
)
NESTING = re.compile(r"scene file '.*scene\.yaml'.* line 1\b.*nest")


def flat_mesh(folder: Path) -> str:
    trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]], process=False).export(
        folder / "flat.stl"
    )
    return GOOD + "obstacles: [{shape: mesh, mesh: flat.stl, xyz: [0.3, 0.3, 0.4]}]\n"


CASES: list[tuple[str, Callable[[Path], str], str | re.Pattern[str]]] = [
    ("alias bomb", lambda _: BOMB, "line 1: anchors (&name) are not allowed"),
    ("alias", lambda _: GOOD + "x: &m 0.1\nsafety_margin: *m\n", "anchors (&name) are not allowed"),
    # our scan stops nesting beyond 16 levels; a newer PyYAML's scanner may stop it first (at
    # 1000), in its own words: either way exit 2 with the file and the line named
    ("deep nesting", lambda _: "a: " + "[" * 100_000 + "]" * 100_000 + "\n", NESTING),
    ("nesting 2000", lambda _: "a: " + "[" * 2_000 + "]" * 2_000 + "\n", NESTING),
    ("nesting 17", lambda _: GOOD + "x: " + "[" * 17 + "]" * 17 + "\n", "line 3: nested more than 16 levels"),
    (
        "duplicate key",
        lambda _: GOOD + CRATE + "obstacles: []\n",
        "duplicate key 'obstacles' (first given at line 3)",
    ),
    (
        "boolean margin",
        lambda _: GOOD + "safety_margin: true\n",
        "safety_margin = True: Input should be a valid number",
    ),
    (
        "numeric string",
        lambda _: GOOD + 'safety_margin: "0.1"\n',
        "safety_margin = '0.1': Input should be a valid number",
    ),
    (
        "boolean count",
        lambda _: GOOD + "planner: {iterations: true}\n",
        "planner.iterations = True: Input should be a valid integer",
    ),
    (
        "huge samples",
        lambda _: GOOD + "planner: {fitness_samples: 20000000}\n",
        "planner.fitness_samples = 20000000: Input should be less than or equal to 4096",
    ),
    (
        "huge duration",
        lambda _: GOOD + "duration: 1.0e5\n",
        "duration = 100000.0: Input should be less than or equal to 600",
    ),
    (
        "subnormal duration",
        lambda _: GOOD + "duration: 5.0e-324\n",
        "duration = 5e-324: Input should be greater than or equal to 0.01",
    ),
    (
        "tiny step",
        lambda _: GOOD + "planner: {verify_step_m: 1.0e-12}\n",
        "planner.verify_step_m = 1e-12: Input should be greater than or equal to 0.0001",
    ),
    (
        "huge self step",
        lambda _: GOOD + "planner: {self_verify_step_m: 0.5}\n",
        "planner.self_verify_step_m = 0.5: Input should be less than or equal to 0.1",
    ),
    (
        "huge population",
        lambda _: GOOD + "planner: {fireflies: 1000000000}\n",
        "planner.fireflies = 1000000000: Input should be less than or equal to 1000",
    ),
    (
        "huge iterations",
        lambda _: GOOD + "planner: {iterations: 1000000000}\n",
        "planner.iterations = 1000000000: Input should be less than or equal to 10000",
    ),
    (
        "long search",
        lambda _: GOOD + "planner: {fireflies: 1000, iterations: 5000}\n",
        "fireflies x (iterations + 1) = 5001000 evaluations; at most 1000000",
    ),
    (
        "huge alpha",
        lambda _: GOOD + "planner: {alpha: 1.0e300}\n",
        "planner.alpha = 1e+300: Input should be less than or equal to 10",
    ),
    (
        "huge weight",
        lambda _: GOOD + "spline: {a: [0, 0, 1.0e300]}\n",
        "spline.a[2] = 1e+300: Input should be less than or equal to 1000000",
    ),
    (
        "huge p",
        lambda _: GOOD + "spline: {p: 1.0e300}\n",
        "spline: p = 1e+300 must be in [1e-06, 1e+12] or .inf",
    ),
    (
        "far obstacle",
        lambda _: GOOD + "obstacles: [{shape: sphere, radius: 0.1, xyz: [1.0e200, 0, 0]}]\n",
        "obstacles[0].xyz[0] = 1e+200: Input should be less than or equal to 100",
    ),
    ("flat mesh", flat_mesh, "is flat (its vertices span no volume), so it has no convex hull"),
    (
        "device as mesh",
        lambda _: GOOD + "obstacles: [{shape: mesh, mesh: /dev/zero, xyz: [0, 0, 0]}]\n",
        "mesh file '/dev/zero' is not a regular file",
    ),
    (
        "folder as mesh",
        lambda d: GOOD + f"obstacles: [{{shape: mesh, mesh: {d}, xyz: [0, 0, 0]}}]\n",
        "is not a regular file (a folder or a device)",
    ),
    (
        "device as robot",
        lambda _: "robot: /dev/zero\n" + GOOD,
        "robot: URDF file '/dev/zero' is not a regular file",
    ),
    (
        "hostile key",
        lambda _: GOOD + "k" * 1_000 + ": 1\n",
        "kkkkkkk...: unknown key; allowed here: name, robot",
    ),
    (
        "hostile name",
        lambda _: (
            GOOD + "obstacles: [{name: " + "n" * 10_000 + ", shape: sphere, radius: 0.1, xyz: [1, 1, 1]}]\n"
        ),
        "obstacles[0].name = 'nnnn",
    ),
    ("not UTF-8", lambda _: "start: \udcff", "is not UTF-8 text"),
]


def write(folder: Path, text: str) -> Path:
    path = folder / "scene.yaml"
    path.write_bytes(text.encode("utf-8", errors="surrogateescape"))
    return path


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture()
def no_search(monkeypatch: pytest.MonkeyPatch) -> None:
    """A search that fails the command (exit 4): hostile input must be refused before one starts."""
    import planning.pipeline.planner

    def refused(*_: object, **__: object) -> None:
        raise AssertionError("the input reached the search")

    monkeypatch.setattr(planning.pipeline.planner, "search", refused)


@pytest.mark.parametrize(("label", "make", "message"), CASES, ids=[c[0] for c in CASES])
@pytest.mark.usefixtures("no_search")
def test_a_hostile_scene_exits_2_at_once_naming_the_field(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    label: str,
    make: Callable[[Path], str],
    message: str | re.Pattern[str],
) -> None:
    scene = write(tmp_path, make(tmp_path))
    out = tmp_path / "out"
    code, stdout, stderr = run(["plan", str(scene), "--out", str(out)], capsys)
    assert code == 2, label
    assert message.search(stderr) if isinstance(message, re.Pattern) else message in stderr, stderr
    short = len(stderr.replace(str(tmp_path), "")) < 400  # each value cut where shown
    assert stderr.count("\n") == 1 and short and "Traceback" not in stderr and stdout == ""
    assert not out.exists()


def test_a_limits_file_that_is_not_utf8_beside_a_urdf(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from cpr_kin import cpr_urdf_path

    (tmp_path / "robot.urdf").write_bytes(cpr_urdf_path().read_bytes())
    (tmp_path / "cpr_limits.yaml").write_bytes(b"theta1: {acceleration: \xff}\n")
    scene = write(tmp_path, GOOD + "robot: robot.urdf\n")
    code, _, stderr = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and "cpr_limits.yaml' is not UTF-8 text (byte 23 is 0xff)" in stderr
    assert stderr.count("\n") == 1 and "Traceback" not in stderr


@pytest.mark.parametrize("out", ["", ".", "scene.yaml"])
def test_unusable_output_folders_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, out: str
) -> None:
    monkeypatch.chdir(tmp_path)
    write(tmp_path, GOOD)
    code, _, stderr = run(["plan", "scene.yaml", "--out", out], capsys)
    assert code == 2 and "output folder" in stderr and stderr.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["scene.yaml"]


@pytest.fixture(scope="module")
def trajectory_file(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    folder = tmp_path_factory.mktemp("check")
    scene = write(folder, GOOD + CRATE + "duration: 4.0\nspline: {ends: natural}\n")
    assert main(["plan", str(scene), "--out", str(folder / "out")]) == 0
    return scene, folder / "out" / "trajectory.json"


def changed(path: Path, edit: Callable[[dict[str, object]], None], target: Path) -> Path:
    document = json.loads(path.read_text())
    edit(document)
    target.write_text(json.dumps(document))
    return target


def shift(segment: int, joint: int, k: int, by: float) -> Callable[[dict[str, object]], None]:
    def edit(document: dict[str, object]) -> None:
        document["segments"][segment]["coeffs"][joint][k] += by  # type: ignore[index]

    return edit


def set_value(segment: int, value: float) -> Callable[[dict[str, object]], None]:
    def edit(document: dict[str, object]) -> None:
        document["segments"][segment]["coeffs"][0][0] = value  # type: ignore[index]

    return edit


@pytest.mark.parametrize(
    ("edit", "code", "message"),
    [
        (
            shift(3, 0, 0, 0.3),
            3,
            "is not continuous (C3) at t = 3 s (knot 3): the position of joint 'theta1' jumps by 0.3 rad",
        ),
        (set_value(1, float("nan")), 2, "segments[1].coeffs[0][0] = nan: Input should be a finite number"),
        (set_value(1, 1e308), 2, "segments[1].coeffs reach 1e+308; no joint moves beyond 1e+06 rad or m"),
        (lambda d: d["segments"][2].update(t0=2.5), 2, "segments[2].t0 = 2.5 s, but the knot there is 2.0 s"),
    ],
)
def test_check_verifies_the_file_as_a_trajectory(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    trajectory_file: tuple[Path, Path],
    edit: Callable[[dict[str, object]], None],
    code: int,
    message: str,
) -> None:
    scene, good = trajectory_file
    bad = changed(good, edit, tmp_path / "bad.json")
    returned, stdout, stderr = run(["check", str(scene), str(bad)], capsys)
    assert returned == code and message in stdout + stderr, stdout + stderr
    assert "Traceback" not in stderr
    if code == 2:  # a malformed file cannot be shown either
        returned, _, stderr = run(["show", str(bad), "--html", str(tmp_path / "v.html")], capsys)
        assert returned == 2 and message in stderr and not (tmp_path / "v.html").exists()


def test_check_accepts_the_file_a_plan_wrote(
    trajectory_file: tuple[Path, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    scene, good = trajectory_file
    code, stdout, _ = run(["check", str(scene), str(good)], capsys)
    assert code == 0 and "verified against" in stdout
    values = np.array(json.loads(good.read_text())["segments"][0]["coeffs"])
    assert np.all(np.isfinite(values))


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    segment=st.integers(0, 3),
    joint=st.integers(0, 4),
    k=st.integers(0, 7),
    value=st.one_of(st.floats(-10.0, 10.0), st.sampled_from([0.0, 1e-9, 1e5, -1e5])),
)
def test_check_of_any_changed_coefficient_ends_in_a_verdict(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    trajectory_file: tuple[Path, Path],
    segment: int,
    joint: int,
    k: int,
    value: float,
) -> None:
    scene, good = trajectory_file

    def edit(document: dict[str, object]) -> None:
        document["segments"][segment]["coeffs"][joint][k] = value  # type: ignore[index]

    bad = changed(good, edit, tmp_path / "fuzzed.json")
    code, _, stderr = run(["check", str(scene), str(bad)], capsys)
    assert code in (0, 2, 3) and "Traceback" not in stderr and stderr.count("\n") <= 1


def rename(first: int, as_name: str) -> Callable[[dict[str, object]], None]:
    def edit(document: dict[str, object]) -> None:
        document["joint_names"][first] = as_name  # type: ignore[index]

    return edit


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (
            shift(3, 0, 0, 0.5),
            "is not continuous (C3) at t = 3 s (knot 3): the position of joint 'theta1' jumps by 0.5 "
            "rad or m",
        ),
        (rename(1, "theta1"), "names ['theta1'] more than once; each joint once"),
        (set_value(1, float("nan")), "segments[1].coeffs[0][0] = nan: Input should be a finite number"),
    ],
)
def test_export_reads_the_file_as_check_does(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    trajectory_file: tuple[Path, Path],
    edit: Callable[[dict[str, object]], None],
    message: str,
) -> None:
    _, good = trajectory_file
    bad = changed(good, edit, tmp_path / "bad.json")
    out = tmp_path / "ros.yaml"
    code, _, stderr = run(["export", str(bad), "--format", "joint-trajectory", "--out", str(out)], capsys)
    assert code == 2 and message in stderr and stderr.count("\n") == 1 and not out.exists()


def test_a_joint_named_twice_fails_check_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], trajectory_file: tuple[Path, Path]
) -> None:
    scene, good = trajectory_file
    bad = changed(good, rename(1, "theta1"), tmp_path / "twice.json")
    code, _, stderr = run(["check", str(scene), str(bad)], capsys)
    assert code == 2 and "names ['theta1'] more than once" in stderr


@pytest.mark.parametrize("link", ["same", "symlink", "hardlink"])
def test_export_and_show_never_write_over_the_trajectory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], trajectory_file: tuple[Path, Path], link: str
) -> None:
    _, good = trajectory_file
    trajectory = tmp_path / "t.json"
    trajectory.write_bytes(good.read_bytes())
    out = {"same": trajectory, "symlink": tmp_path / "out.json", "hardlink": tmp_path / "out.json"}[link]
    if link == "symlink":
        out.symlink_to(trajectory)
    elif link == "hardlink":
        out.hardlink_to(trajectory)
    for command in (
        ["export", str(trajectory), "--format", "joint-trajectory", "--out", str(out)],
        ["show", str(trajectory), "--html", str(out)],
    ):
        code, _, stderr = run(command, capsys)
        assert code == 2 and f"is the trajectory file '{trajectory}', an input of this command" in stderr
        assert trajectory.read_bytes() == good.read_bytes()
