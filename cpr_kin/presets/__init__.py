"""Robots the toolkit knows by name: a preset is a :class:`~cpr_kin.RobotSpec` with its files.

The CPR (:mod:`cpr_kin.presets.cpr`): the bundled 5-DOF cylindrical arm of the paper, its
spec, default limits and analytic IK of a tool position (:mod:`cpr_kin.presets.cpr_ik`).
:func:`robot_spec` gives a URDF the preset it matches (a CPR variant: the CPR's joint names),
else the generic rules every other robot loads by.
"""

from __future__ import annotations

from pathlib import Path

from cpr_kin.description.loading import RobotSpec
from cpr_kin.presets.cpr import (
    CPR_JOINTS,
    TCP_FRAME,
    cpr_limits_path,
    cpr_spec,
    cpr_urdf_path,
    has_cpr_joints,
    load_cpr,
)
from cpr_kin.presets.cpr_ik import tcp_ik

__all__ = [
    "CPR_JOINTS",
    "TCP_FRAME",
    "cpr_limits_path",
    "cpr_spec",
    "cpr_urdf_path",
    "load_cpr",
    "robot_spec",
    "tcp_ik",
]


def robot_spec(urdf_path: str | Path) -> RobotSpec:
    """The spec of the robot of a URDF: the CPR preset for a CPR variant, else the generic rules."""
    path = Path(urdf_path)
    return cpr_spec(path) if path.is_file() and has_cpr_joints(path) else RobotSpec(urdf=path)
