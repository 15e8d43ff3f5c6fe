"""Paths of the files bundled with the project: the CPR's URDF and its limits.

In a source checkout (and an editable install) they are the repository's ``urdf/`` folder;
an installed wheel carries the same folder as the package data ``cpr_kin.urdf``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def bundled_urdf_dir() -> Path:
    """Folder that holds ``cpr.urdf`` and ``cpr_limits.yaml``."""
    checkout = Path(__file__).resolve().parent.parent / "urdf"
    if (checkout / "cpr.urdf").is_file():
        return checkout
    # ``cpr_kin.urdf`` has no ``__init__.py``: ask its parent package, whose files() is a plain path
    return Path(str(resources.files("cpr_kin") / "urdf"))


def cpr_urdf_path() -> Path:
    """Path of the bundled CPR URDF."""
    return bundled_urdf_dir() / "cpr.urdf"


def cpr_limits_path() -> Path:
    """Path of the bundled acceleration and jerk limits of the CPR."""
    return bundled_urdf_dir() / "cpr_limits.yaml"
