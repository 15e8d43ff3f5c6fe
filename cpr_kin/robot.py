"""A serial robot from its URDF: Pinocchio models, joint limits and collision groups, built once.

:func:`load_robot` reads a URDF (strict XML, validated by yourdfpy), checks that the planner
supports it (:mod:`cpr_kin.supported`: joint types, ranges, limits, printable names), builds
Pinocchio's kinematic, collision and visual models, reads the acceleration and jerk limits
(:mod:`cpr_kin.limits`) and sorts the collision geometry into two groups:

- ``effector``: the links named as the effector (wrist and tool);
- ``links``: everything else.

A robot's preset (:mod:`cpr_kin.cpr` for the CPR) names those links, its tool frame and the
joints it holds unless asked to move them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.errors import CprKinError, JointLimitError, UrdfError
from cpr_kin.limits import JointLimits, find_limits_file, read_dynamic_limits
from cpr_kin.supported import check_joints, check_limits, check_names
from cpr_kin.urdf_file import captured_stderr, collision_names, is_bundled, parse_urdf, validate_urdf

FloatArray = NDArray[np.float64]

GROUPS = ("effector", "links")
"""Collision group names, in the order used by every per-group array."""


@dataclass(frozen=True)
class RobotGeometry:
    """One collision geometry of the robot.

    Attributes:
        name: geometry name (the URDF ``<collision name=...>``, else the link name).
        link: URDF link it belongs to.
        group: ``"effector"`` or ``"links"``.
        index: index in the Pinocchio geometry model.

    """

    name: str
    link: str
    group: str
    index: int


@dataclass(frozen=True, eq=False)
class Robot:
    """A robot's Pinocchio models, limits and collision groups.

    Build it with :func:`load_robot` (or a preset such as :func:`cpr_kin.load_cpr`).

    Attributes:
        urdf_path: the URDF it was built from.
        model: Pinocchio kinematic model.
        collision_model: Pinocchio geometry model of the robot's collision shapes.
        visual_model: Pinocchio geometry model of the visual shapes.
        limits: joint limits, in configuration order.
        geometries: the robot's collision geometries with their groups.
        tcp_frame: the tool-centre-point frame (the default frame of the kinematics).
        wrist_joints: joints a plan holds unless its start and goal differ in them.
        limits_path: the file the acceleration and jerk limits were read from.

    """

    urdf_path: Path
    model: Any
    collision_model: Any
    visual_model: Any
    limits: JointLimits
    geometries: tuple[RobotGeometry, ...]
    _data: Any = field(repr=False)
    tcp_frame: str = "tcp"
    wrist_joints: tuple[str, ...] = ()
    limits_path: Path | None = None

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint names in configuration order."""
        return self.limits.names

    @property
    def nq(self) -> int:
        """Number of joints."""
        return len(self.limits.names)

    @property
    def data(self) -> Any:
        """A Pinocchio ``Data`` of :attr:`model`, shared by this robot's own computations."""
        return self._data

    def frame_id(self, frame: str) -> int:
        """Pinocchio id of ``frame``; raises :class:`CprKinError` naming the known frames."""
        if not self.model.existFrame(frame):
            known = sorted({f.name for f in self.model.frames})
            raise CprKinError(f"unknown frame '{frame}'; the robot's frames are {known}")
        return int(self.model.getFrameId(frame))

    def configuration(self, values: ArrayLike | dict[str, float], *, check_limits: bool = True) -> FloatArray:
        """Validate a joint vector and return it as a float array of shape ``(nq,)``.

        Args:
            values: ``nq`` numbers in joint order, or a mapping ``{joint name: value}`` that
                names every joint.
            check_limits: also require every value to lie within its joint's range.

        Raises:
            JointLimitError: wrong length, non-finite value, unknown joint or value outside
                the limits; the message names the joint, the value and the range.

        """
        if isinstance(values, dict):
            for name in values:
                self.limits.index(name)
            missing = [n for n in self.joint_names if n not in values]
            if missing:
                raise JointLimitError(f"joint values {values} lack joint(s) {missing}")
            q = np.array([values[n] for n in self.joint_names], dtype=float)
        else:
            try:
                q = np.array(values, dtype=float)
            except (TypeError, ValueError):
                raise JointLimitError(
                    f"joint vector {values!r} must be {self.nq} numbers {list(self.joint_names)}"
                ) from None
        if q.shape != (self.nq,):
            raise JointLimitError(
                f"joint vector {np.asarray(values).tolist()} has shape {q.shape}; expected "
                f"{self.nq} values for {list(self.joint_names)}"
            )
        for i, name in enumerate(self.joint_names):
            if not np.isfinite(q[i]):
                raise JointLimitError(f"joint '{name}' = {q[i]} is not a finite number")
            if check_limits:
                self.check_joint(name, float(q[i]))
        return q

    def check_joint(self, name: str, value: float, tol: float = 1e-12) -> None:
        """Raise :class:`JointLimitError` if joint ``name`` = ``value`` is outside its range."""
        i = self.limits.index(name)
        lo, hi = self.limits.lower[i], self.limits.upper[i]
        if not lo - tol <= value <= hi + tol:
            unit = self.joint_unit(name)
            raise JointLimitError(f"joint '{name}' = {value:.6g} {unit} is outside [{lo:g}, {hi:g}] {unit}")

    def joint_unit(self, name: str) -> str:
        """``"rad"`` for a revolute joint, ``"m"`` for a prismatic one."""
        joint = self.model.joints[self.limits.index(name) + 1]
        return "m" if joint.shortname().removeprefix("JointModel").startswith("P") else "rad"

    def group_geometries(self, group: str) -> Sequence[RobotGeometry]:
        """Geometries of collision group ``group`` (one of :data:`GROUPS`)."""
        if group not in GROUPS:
            raise CprKinError(f"unknown collision group '{group}'; allowed: {list(GROUPS)}")
        return [g for g in self.geometries if g.group == group]


def load_robot(
    urdf_path: str | Path,
    limits_path: str | Path | None = None,
    *,
    joints: Sequence[str] | None = None,
    effector_links: Sequence[str] = (),
    tcp_frame: str = "tcp",
    wrist_joints: Sequence[str] = (),
    default_limits: Path | None = None,
    validate: bool | None = None,
) -> Robot:
    """Validate and load the serial robot of a URDF.

    Args:
        urdf_path: the URDF.
        limits_path: its acceleration and jerk limits (YAML); default: the file
            :func:`~cpr_kin.limits.find_limits_file` finds beside the URDF, else
            ``default_limits``.
        joints: the joint names the URDF must have, in configuration order (a preset's);
            default: any.
        effector_links: links whose collision geometry forms the ``effector`` group.
        tcp_frame: the tool-centre-point frame, which must exist.
        wrist_joints: joints a plan holds unless its start and goal differ in them.
        default_limits: the limits file used when none is given or found beside the URDF.
        validate: check the URDF's structure with yourdfpy (links, joints, their
            references). Default: for every URDF but the bundled CPR's, which the test suite
            validates; this saves each process that loads it about 0.7 s.

    Raises:
        UrdfError: the file is missing or malformed, a joint or limit the planner does not
            support, no limits file, or a group or frame missing.

    """
    path = Path(urdf_path)
    tree = parse_urdf(path)
    if validate or (validate is None and not is_bundled(path)):
        validate_urdf(path)
    check_names(tree, path)
    check_joints(tree, path)
    try:
        with captured_stderr() as complaints:  # urdfdom prints to fd 2; a model that builds needs none
            model, collision_model, visual_model = pin.buildModelsFromUrdf(str(path), str(path.parent))
    except Exception as exc:  # Pinocchio reports C++ exceptions as RuntimeError/ValueError
        said = " ".join(line.strip() for line in complaints[:2])
        raise UrdfError(f"Pinocchio cannot build a model from '{path}': {exc} {said}".strip()) from None
    if not model.existFrame(tcp_frame):
        raise UrdfError(f"URDF '{path}' has no link or frame named '{tcp_frame}' (the tool tip)")
    names = tuple(model.names[1:])
    if joints is not None and names != tuple(joints):
        missing = [j for j in joints if j not in names]
        raise UrdfError(
            f"URDF '{path}' has joints {list(names)}; this robot needs exactly "
            f"{list(joints)} in this order" + (f" (missing {missing})" if missing else "")
        )
    limits_file = Path(limits_path) if limits_path is not None else find_limits_file(path, default_limits)
    velocity = np.array(model.velocityLimit, dtype=float)
    acceleration, jerk = read_dynamic_limits(limits_file, names, velocity)
    limits = JointLimits(
        names=names,
        lower=np.array(model.lowerPositionLimit, dtype=float),
        upper=np.array(model.upperPositionLimit, dtype=float),
        velocity=velocity,
        acceleration=acceleration,
        jerk=jerk,
    )
    check_limits(limits, _units(model), path)
    geometries = _geometries(model, collision_model, collision_names(tree), set(effector_links))
    for group in GROUPS:
        if not any(g.group == group for g in geometries):
            raise UrdfError(f"URDF '{path}' has no collision geometry in group '{group}'")
    return Robot(
        urdf_path=path,
        model=model,
        collision_model=collision_model,
        visual_model=visual_model,
        limits=limits,
        geometries=geometries,
        _data=model.createData(),
        tcp_frame=tcp_frame,
        wrist_joints=tuple(wrist_joints),
        limits_path=limits_file,
    )


def _units(model: Any) -> tuple[str, ...]:
    """``"rad"`` or ``"m"`` per joint of ``model``."""
    return tuple(
        "m" if joint.shortname().removeprefix("JointModel").startswith("P") else "rad"
        for joint in model.joints[1:]
    )


def _geometries(
    model: Any, collision_model: Any, names_by_link: dict[str, list[str]], effector: set[str]
) -> tuple[RobotGeometry, ...]:
    """The collision geometries, named as in the URDF and sorted into their groups."""
    geometries = []
    used: dict[str, int] = {}
    for index, obj in enumerate(collision_model.geometryObjects):
        link = model.frames[obj.parentFrame].name
        k = used.get(link, 0)
        used[link] = k + 1
        name = names_by_link[link][k]
        obj.name = name
        group = "effector" if link in effector else "links"
        geometries.append(RobotGeometry(name=name, link=link, group=group, index=index))
    return tuple(geometries)
