"""The README's and the docs' Python snippets run, and the README's scene is the example file.

Each ```python block of a file builds on the ones before it, as a reader would type them,
in one namespace per file (as newer mink's do). They run in a temporary working folder, so
the files they write land there.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = sorted((ROOT / "docs").glob("*.md"))


def blocks(path: Path, language: str) -> list[str]:
    return re.findall(rf"^```{language}\n(.*?)^```", path.read_text(), flags=re.MULTILINE | re.DOTALL)


def run_snippets(path: Path) -> None:
    namespace: dict[str, object] = {"__name__": "readme"}
    for number, code in enumerate(blocks(path, "python"), start=1):
        try:
            exec(compile(code, f"{path.name} snippet {number}", "exec"), namespace)
        except Exception as exc:  # name the snippet that broke
            raise AssertionError(f"{path.name} snippet {number} fails: {exc!r}\n{code}") from exc


def test_the_readme_has_snippets() -> None:
    assert len(blocks(README, "python")) >= 3


def test_readme_snippets_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    run_snippets(README)
    assert (tmp_path / "out" / "trajectory.json").is_file()
    assert os.listdir(tmp_path)  # what the snippets write stays in the temporary folder


@pytest.mark.parametrize("page", [p for p in DOCS if blocks(p, "python")], ids=lambda p: p.name)
def test_docs_snippets_run(page: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    run_snippets(page)


def test_the_readmes_scene_is_the_example_file_and_plans_from_where_it_lies(tmp_path: Path) -> None:
    from planning import load_scene

    scene, _, payload = blocks(README, "yaml")
    example = ROOT / "examples" / "scenes" / "shelf.yaml"
    assert scene == example.read_text()
    loaded = load_scene(example)  # robot: resolves relative to the scene file, from any folder
    assert loaded.robot is not None
    assert loaded.robot.urdf == (ROOT / "urdf" / "cpr.urdf").resolve()
    from cpr_kin.common.user_files import load_yaml
    from planning.io.scene_file import parse_scene

    (tmp_path / "carried.yaml").write_text(scene + payload)
    carried = parse_scene(load_yaml(tmp_path / "carried.yaml", 100_000, "scene"), base=example.parent)
    assert carried.payload is not None and carried.payload.mass_kg == 3.0 and carried.torque_scale == 0.9


def test_bring_your_own_robot_runs_as_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import shlex

    import yaml

    import cpr_kin as ck
    from planning.cli import main
    from planning.io.scene_file import parse_scene

    _, fragment, _ = blocks(README, "yaml")
    # a scene's robot must name a URDF file: the CPR's stands in for the reader's arm
    (tmp_path / "my_arm.urdf").write_text(ck.cpr_urdf_path().read_text())
    own = parse_scene(yaml.safe_load(fragment), base=tmp_path)
    assert own.robot is not None and own.robot.urdf.name == "my_arm.urdf" and own.goal.pose is not None
    panda = next(block for block in blocks(README, "sh") if "panda_post.yaml" in block)
    commands = [line.split("#")[0] for line in panda.splitlines() if line.strip()]
    monkeypatch.chdir(ROOT)
    for command in commands:
        words = shlex.split(command.replace("out/panda", str(tmp_path / "panda")))
        assert words[0] == "cpr-plan" and main(words[1:]) == 0, command
    assert (tmp_path / "panda" / "viewer.html").is_file()


def test_nothing_points_outside_the_repository() -> None:
    texts = [README, *DOCS, *ROOT.glob("planning/**/*.py"), *ROOT.glob("cpr_kin/**/*.py")]
    offenders = [
        str(p.relative_to(ROOT)) for p in texts if re.search(r"DESIGN\.md|\.\./shared", p.read_text())
    ]
    assert offenders == []


def test_every_docs_page_the_readme_links_exists() -> None:
    linked = re.findall(r"\]\((docs/[^)#]+)", README.read_text())
    assert linked and all((ROOT / link).is_file() for link in linked)
    assert {f"docs/{p.name}" for p in DOCS} - {"docs/index.md"} <= set(linked)
