"""The CPR robot: URDF validation and Pinocchio models, built once and reused.

A :class:`Robot` holds the Pinocchio kinematic model, its collision geometry model, the
joint limits and the two collision groups of DESIGN.md section 3:

- ``effector``: the wrist and the tool;
- ``links``: everything else (base, column, carriage, arm beam).
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
from cpr_kin.limits import JointLimits, read_dynamic_limits
from cpr_kin.resources import cpr_limits_path, cpr_urdf_path
from cpr_kin.urdf_file import collision_names, is_bundled, parse_urdf, validate_urdf

FloatArray = NDArray[np.float64]

CPR_JOINTS = ("theta1", "d2", "d3", "theta4", "theta5")
"""Joint names of the CPR, in configuration order."""

TCP_FRAME = "tcp"
"""Name of the tool-centre-point frame."""

EFFECTOR_LINKS = ("wrist_link", "tool_link")
"""Links whose collision geometry forms the ``effector`` group; the rest form ``links``."""

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
    """The CPR's Pinocchio models, limits and collision groups.

    Build it with :meth:`Robot.load` (or :func:`load_cpr` for the bundled robot).

    Attributes:
        urdf_path: the URDF it was built from.
        model: Pinocchio kinematic model.
        collision_model: Pinocchio geometry model of the robot's collision shapes.
        visual_model: Pinocchio geometry model of the visual shapes.
        limits: joint limits, in configuration order.
        geometries: the robot's collision geometries with their groups.

    """

    urdf_path: Path
    model: Any
    collision_model: Any
    visual_model: Any
    limits: JointLimits
    geometries: tuple[RobotGeometry, ...]
    _data: Any = field(repr=False)

    @classmethod
    def load(
        cls,
        urdf_path: str | Path | None = None,
        limits_path: str | Path | None = None,
        validate: bool | None = None,
    ) -> Robot:
        """Validate and load a CPR URDF.

        Args:
            urdf_path: the URDF; default: the bundled ``urdf/cpr.urdf``.
            limits_path: acceleration/jerk limits YAML; default: ``cpr_limits.yaml`` next to
                the URDF, else the bundled one.
            validate: check the URDF's structure with yourdfpy (links, joints, their
                references). Default: for every URDF but the bundled one, which the test
                suite validates; this saves each process that loads it about 0.7 s.

        Raises:
            UrdfError: the file is missing or malformed, or lacks a CPR joint or the tcp frame.

        """
        path = Path(urdf_path) if urdf_path is not None else cpr_urdf_path()
        tree = parse_urdf(path)
        if validate or (validate is None and not is_bundled(path)):
            validate_urdf(path)
        try:
            model, collision_model, visual_model = pin.buildModelsFromUrdf(str(path), str(path.parent))
        except Exception as exc:  # Pinocchio reports C++ exceptions as RuntimeError/ValueError
            raise UrdfError(f"Pinocchio cannot build a model from '{path}': {exc}") from None

        names = tuple(model.names[1:])
        if names != CPR_JOINTS or model.nq != len(CPR_JOINTS):
            missing = [j for j in CPR_JOINTS if j not in names]
            raise UrdfError(
                f"URDF '{path}' has joints {list(names)}; the CPR needs exactly "
                f"{list(CPR_JOINTS)} in this order" + (f" (missing {missing})" if missing else "")
            )
        if not model.existFrame(TCP_FRAME):
            raise UrdfError(f"URDF '{path}' has no link or frame named '{TCP_FRAME}' (the tool tip)")

        if limits_path is None:
            beside = path.parent / "cpr_limits.yaml"
            limits_path = beside if beside.is_file() else cpr_limits_path()
        velocity = np.array(model.velocityLimit, dtype=float)
        acceleration, jerk = read_dynamic_limits(Path(limits_path), names, velocity)
        limits = JointLimits(
            names=names,
            lower=np.array(model.lowerPositionLimit, dtype=float),
            upper=np.array(model.upperPositionLimit, dtype=float),
            velocity=velocity,
            acceleration=acceleration,
            jerk=jerk,
        )

        names_by_link = collision_names(tree)
        geometries = []
        used: dict[str, int] = {}
        for index, obj in enumerate(collision_model.geometryObjects):
            link = model.frames[obj.parentFrame].name
            k = used.get(link, 0)
            used[link] = k + 1
            name = names_by_link[link][k]
            obj.name = name
            group = "effector" if link in EFFECTOR_LINKS else "links"
            geometries.append(RobotGeometry(name=name, link=link, group=group, index=index))
        for group in GROUPS:
            if not any(g.group == group for g in geometries):
                raise UrdfError(f"URDF '{path}' has no collision geometry in group '{group}'")
        return cls(
            urdf_path=path,
            model=model,
            collision_model=collision_model,
            visual_model=visual_model,
            limits=limits,
            geometries=tuple(geometries),
            _data=model.createData(),
        )

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


def load_cpr(urdf_path: str | Path | None = None) -> Robot:
    """Load the CPR (default: the bundled URDF). See :meth:`Robot.load`."""
    return Robot.load(urdf_path)
