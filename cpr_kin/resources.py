"""Paths of the files bundled with the project: the CPR's URDF and its limits.

They are the package data ``cpr_kin/urdf/``, the same folder in a checkout, an editable
install and an installed wheel.
"""

from __future__ import annotations

from pathlib import Path


def bundled_urdf_dir() -> Path:
    """Folder that holds ``cpr.urdf`` and ``cpr_limits.yaml``."""
    return Path(__file__).resolve().parent / "urdf"


def cpr_urdf_path() -> Path:
    """Path of the bundled CPR URDF."""
    return bundled_urdf_dir() / "cpr.urdf"


def cpr_limits_path() -> Path:
    """Path of the bundled acceleration and jerk limits of the CPR."""
    return bundled_urdf_dir() / "cpr_limits.yaml"
