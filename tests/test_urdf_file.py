"""``cpr_kin.description.urdf_file``: yourdfpy's verdict on a URDF, remembered only where it is valid."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import cpr_kin as ck
from cpr_kin.description import urdf_file

URDF_TEXT = ck.cpr_urdf_path().read_text()


@pytest.fixture
def validations(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> list[Path]:
    """The files yourdfpy validates, in a cache folder of the test's own."""
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))
    validated: list[Path] = []
    original = urdf_file._validated

    def counted(path: Path) -> Any:
        validated.append(path)
        return original(path)

    monkeypatch.setattr(urdf_file, "_validated", counted)
    return validated


def test_a_valid_urdf_is_validated_once_per_content(tmp_path: Path, validations: list[Path]) -> None:
    path = tmp_path / "arm.urdf"
    path.write_text(URDF_TEXT)
    urdf_file.validate_urdf(path)
    urdf_file.validate_urdf(path)
    copy = tmp_path / "elsewhere.urdf"  # the same bytes under another name: the same verdict
    copy.write_text(URDF_TEXT)
    urdf_file.validate_urdf(copy)
    assert validations == [path]
    path.write_text(URDF_TEXT.replace('name="cpr"', 'name="cpr_edited"', 1))  # new bytes: asked again
    urdf_file.validate_urdf(path)
    assert validations == [path, path]


def test_an_invalid_urdf_is_refused_every_time_and_nothing_is_kept(
    tmp_path: Path, validations: list[Path]
) -> None:
    path = tmp_path / "hinge.urdf"
    path.write_text(URDF_TEXT.replace('type="revolute"', 'type="hinge"', 1))
    for _ in range(2):
        with pytest.raises(ck.UrdfError, match=r"hinge\.urdf' is invalid: .*'type' attribute"):
            urdf_file.validate_urdf(path)
    assert validations == [path, path]
    assert not list((tmp_path / "cache").glob("urdf-valid/*"))
