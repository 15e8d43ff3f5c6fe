"""Paths of the files bundled with the project: the CPR's URDF and its limits, the makers' limits.

They are the package ``cpr_kin.urdf``: the repository's top-level ``urdf/`` folder, which
``pyproject.toml`` maps to that package in an editable install and in the wheel.
"""

from __future__ import annotations

from collections.abc import Iterable
from importlib import import_module
from pathlib import Path

import yaml


def bundled_urdf_dir() -> Path:
    """Folder that holds ``cpr.urdf``, ``cpr_limits.yaml`` and ``makers/`` (the package ``cpr_kin.urdf``)."""
    return Path(import_module("cpr_kin.urdf").__file__ or "").resolve().parent


def makers_limits_path(robot_name: str, joints: Iterable[str]) -> Path | None:
    """The limits file shipped for a URDF whose ``<robot name>`` is ``robot_name``, if any.

    ``urdf/makers/<name>_limits.yaml``: acceleration and jerk limits from an arm
    maker's datasheet (the Panda's), used when no limits file lies beside the URDF and the
    URDF has every joint the file names (``joints``: the URDF's).
    """
    path = bundled_urdf_dir() / "makers" / f"{robot_name}_limits.yaml"
    if not robot_name or not path.is_file():
        return None
    named = yaml.safe_load(path.read_text(encoding="utf-8"))
    return path if set(named) <= set(joints) else None
