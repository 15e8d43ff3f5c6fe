"""The CPR preset: the bundled 5-DOF cylindrical arm (R-P-P:R-R) as a :class:`~cpr_kin.model.robot.Robot`.

What makes a URDF the CPR: joints ``theta1 d2 d3 theta4 theta5`` in this order, a ``tcp``
frame at the tool tip, and the wrist and tool links that form the ``effector`` group. A CPR
variant (other lengths, ranges or limits) is a URDF with the same names. Its acceleration
and jerk limits: the file :func:`~cpr_kin.model.limits.find_limits_file` finds beside the URDF,
then ``cpr_limits.yaml`` beside it, else the bundled CPR's. Its self-collision pairs: an
SRDF beside it, else the bundled ``cpr.srdf`` (which disables every pair: the CPR cannot
meet itself).
"""

from __future__ import annotations

from pathlib import Path

from cpr_kin.description.loading import RobotSpec
from cpr_kin.description.resources import bundled_urdf_dir
from cpr_kin.description.urdf_file import parse_urdf
from cpr_kin.model.limits import LIMITS_NAMES
from cpr_kin.model.robot import Robot
from cpr_kin.presets.cpr_ik import WRIST_JOINTS, position_ik

CPR_JOINTS = ("theta1", "d2", "d3", "theta4", "theta5")
"""Joint names of the CPR, in configuration order."""
TCP_FRAME = "tcp"
"""Name of the tool-centre-point frame."""
EFFECTOR_LINKS = ("wrist_link", "tool_link")
"""Links whose collision geometry forms the ``effector`` group; the rest form ``links``."""


def cpr_urdf_path() -> Path:
    """Path of the bundled CPR URDF."""
    return bundled_urdf_dir() / "cpr.urdf"


def cpr_limits_path() -> Path:
    """Path of the bundled acceleration and jerk limits of the CPR."""
    return bundled_urdf_dir() / "cpr_limits.yaml"


def load_cpr(
    urdf_path: str | Path | None = None, limits_path: str | Path | None = None, validate: bool | None = None
) -> Robot:
    """Load the CPR: the bundled URDF, or a variant of it with the same joint names.

    Args:
        urdf_path: the URDF; default: the bundled ``urdf/cpr.urdf``.
        limits_path: acceleration and jerk limits; default: see the module docstring.
        validate: validate the URDF with yourdfpy; default: yes, but the bundled file (which
            the test suite validates).

    Raises:
        UrdfError: the file is missing, malformed or unsupported, or lacks a CPR joint or
            the ``tcp`` frame.
    """
    return cpr_spec(urdf_path, limits_path, validate).load()


def cpr_spec(
    urdf_path: str | Path | None = None, limits_path: str | Path | None = None, validate: bool | None = None
) -> RobotSpec:
    """The :class:`~cpr_kin.description.loading.RobotSpec` of the CPR preset (see :func:`load_cpr`)."""
    urdf = Path(urdf_path) if urdf_path is not None else cpr_urdf_path()
    bundled = urdf.resolve() == cpr_urdf_path().resolve()
    return RobotSpec(
        urdf=urdf,
        limits=None if limits_path is None else Path(limits_path),
        joints=CPR_JOINTS,
        tcp=TCP_FRAME,
        effector_links=EFFECTOR_LINKS,
        wrist_joints=WRIST_JOINTS,
        position_ik=position_ik,
        limits_names=(*LIMITS_NAMES, "cpr_limits.yaml"),
        default_limits=cpr_limits_path(),
        default_srdf=cpr_limits_path().with_name("cpr.srdf"),
        validate=validate if validate is not None else not bundled,
    )


def has_cpr_joints(urdf_path: Path) -> bool:
    """Whether the URDF at ``urdf_path`` has exactly the CPR's joints (a CPR variant)."""
    tree = parse_urdf(urdf_path)
    moving = tuple(j.get("name") for j in tree.getroot().findall("joint") if j.get("type") != "fixed")
    return moving == CPR_JOINTS
