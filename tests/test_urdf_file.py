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

    def counted(path: Path, content: bytes) -> Any:
        validated.append(path)
        return original(path, content)

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


def test_the_bytes_read_are_the_bytes_validated(tmp_path: Path) -> None:
    """The verdict is kept under the digest of the bytes read first: those are validated, not the
    file read again (an edit in between would otherwise have its verdict kept for the old bytes)."""
    path = tmp_path / "arm.urdf"
    path.write_text(URDF_TEXT.replace('type="revolute"', 'type="hinge"', 1))  # the file as it is now
    assert urdf_file._validated(path, URDF_TEXT.encode()) == {"valid": True}  # the bytes read before
    path.write_text(URDF_TEXT)
    with pytest.raises(ck.UrdfError, match=r"arm\.urdf' is invalid: .*'type' attribute"):
        urdf_file._validated(path, URDF_TEXT.replace('type="revolute"', 'type="hinge"', 1).encode())


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


@pytest.mark.parametrize(
    "declared", ['<?xml version="0.0" ?>', "\ufeff<?xml version='2.0' encoding='utf-8'?>"]
)
def test_a_declared_xml_version_other_than_1_is_read_as_1_0(
    tmp_path: Path, validations: list[Path], caplog: pytest.LogCaptureFixture, declared: str
) -> None:
    # pybullet's Minitaur, quadruped and WSG-50 gripper declare version 0.0: libxml2 refused them,
    # while urdfdom (Pinocchio's parser) reads them as XML 1.0
    path = tmp_path / "old.urdf"
    path.write_text(URDF_TEXT.replace('<?xml version="1.0"?>', declared, 1), encoding="utf-8")
    robot = ck.load_cpr(path)
    assert robot.joint_names == ck.load_cpr().joint_names
    assert validations == [path]  # yourdfpy's verdict asked, on the same text, and found valid
    assert "version" not in caplog.text  # nor did yourdfpy log that it parsed another way


def test_a_declaration_of_xml_1_x_and_a_file_without_one_are_read_as_written() -> None:
    for data in (b'<?xml version="1.0"?><robot/>', b"<?xml version='1.1'?><robot/>", b"<robot/>"):
        assert urdf_file.as_xml_1_0(data) is data
    assert urdf_file.as_xml_1_0(b"<?xml version='0.0'?>\n<robot/>") == b"<?xml version='1.0'?>\n<robot/>"
