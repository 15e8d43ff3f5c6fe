"""The README's Python snippets run, in order, in one namespace (as newer mink's do).

Each ```python block builds on the ones before it, as a reader would type them. They run in
a temporary working folder, so the files they write land there.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def snippets() -> list[str]:
    return re.findall(r"^```python\n(.*?)^```", README.read_text(), flags=re.MULTILINE | re.DOTALL)


def test_the_readme_has_snippets() -> None:
    assert len(snippets()) >= 3


def test_readme_snippets_run(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {"__name__": "readme"}
    for number, code in enumerate(snippets(), start=1):
        try:
            exec(compile(code, f"README.md snippet {number}", "exec"), namespace)
        except Exception as exc:  # name the snippet that broke
            raise AssertionError(f"README snippet {number} fails: {exc!r}\n{code}") from exc
    assert (tmp_path / "out" / "trajectory.json").is_file()
    assert os.listdir(tmp_path)  # what the snippets write stays in the temporary folder
