"""A loaded robot: Pinocchio models, joint limits and collision groups, built once.

:func:`cpr_kin.load_robot` (:mod:`cpr_kin.description.loading`) builds one from any serial URDF; a
preset (:mod:`cpr_kin.presets`) names its joints, tool frame, effector links, wrist joints
and its own IK of a tool position. The collision geometry forms two groups:

- ``effector``: the wrist and the tool (the links a preset names, by default those the last
  planned joint moves alone);
- ``links``: everything else.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import CprKinError, JointLimitError
from cpr_kin.model.frames import frame_index, link_names
from cpr_kin.model.limits import JointLimits

if TYPE_CHECKING:  # a robot of pairs of its own or exact meshes imports what they are
    from cpr_kin.bounds.close_pairs import ClosePair
    from cpr_kin.shapes.exact_meshes import ExactMesh

FloatArray = NDArray[np.float64]


class PositionIk(Protocol):
    """A robot's own IK of a tool position (a preset's analytic solver).

    Called as ``ik(robot, tcp_in_base, held)``: the configuration [rad, m] that puts the tool
    frame at ``tcp_in_base`` [m] with the joints ``held`` names at those values (the robot's
    wrist joints at 0 unless named). It raises :class:`~cpr_kin.common.errors.UnreachableError`
    where it finds none; its answer is verified by forward kinematics before it is used.
    """

    def __call__(self, robot: Robot, tcp_in_base: FloatArray, held: Mapping[str, float]) -> FloatArray:
        """The configuration [rad, m] (class docstring)."""
        ...


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
        carried: an object the robot carries (:func:`cpr_kin.carrying`), not one of its links.
        touches: the obstacles a carried object may touch (its payload's ``touch_obstacles``).

    """

    name: str
    link: str
    group: str
    index: int
    carried: bool = False
    touches: tuple[str, ...] = ()


@dataclass(frozen=True, eq=False)
class Robot:
    """A robot's Pinocchio models, limits and collision groups.

    Build it with :func:`cpr_kin.load_robot` (or a preset's loader, :mod:`cpr_kin.presets`).

    Attributes:
        urdf_path: the URDF it was built from.
        model: Pinocchio kinematic model.
        collision_model: Pinocchio geometry model of the robot's collision shapes.
        visual_model: Pinocchio geometry model of the visual shapes, built on first use (only
            a viewer needs it, and a robot's detailed meshes take a while to load).
        limits: joint limits, in configuration order.
        geometries: the robot's collision geometries with their groups.
        tcp_frame: the tool-centre-point frame (the default frame of the kinematics).
        wrist_joints: joints a plan holds unless its start and goal differ in them, and a
            ``tcp`` goal holds at the values it gives (default 0).
        position_ik: the robot's own IK of a tool position, or ``None`` (:class:`PositionIk`).
        limits_path: the file the acceleration and jerk limits were read from (``None``:
            the documented defaults, :func:`cpr_kin.model.limits.default_limits`).
        limits_defaulted: the joints whose acceleration or jerk limit is a default.
        ranges_narrowed: the planned joints whose URDF range passes one turn either way, with
            that range [rad]: each is planned within its part of ``[-2 pi, 2 pi]`` (``limits``).
        held: the URDF's joints that are not planned, at the values they are held at.
        base_joints: the URDF's ``planar`` and ``floating`` joints (a mobile base's), never
            planned and held at their identity pose: the scene's frame is their child link's.
        srdf_path: the SRDF whose ``disable_collisions`` were applied, if any.
        self_pairs: indices of the collision geometry pairs checked against each other
            (:mod:`cpr_kin.collision.self_collision`); empty: the robot cannot meet itself.
        srdf_unknown_links: links the SRDF names that the URDF lacks (their entries skipped).
        overlapping_links: link pairs whose shapes collide in every sampled configuration,
            touching by design and not checked (:mod:`cpr_kin.bounds.overlapping_pairs`).
        close_pairs: checked pairs a few millimetres apart in every sampled configuration where
            they do not meet, held to contact only by a self margin above their largest
            distance (:mod:`cpr_kin.bounds.close_pairs`).
        massless_links: links a planned joint moves that have a shape but no ``<inertial>``
            (massless, the URDF's rule; :mod:`cpr_kin.kinematics.dynamics`).
        capsule_meshes: collision geometries whose convex hull coal cannot hold (a vertex
            with more than 255 neighbours) or that have none (a flat mesh), checked as their
            bounding capsule instead.
        exact_meshes: by geometry index, the link meshes their shapes (hulls, capsules) exceed
            by more than :data:`cpr_kin.shapes.exact_meshes.REFINED_ABOVE_M`: those shapes are bounds,
            and the meshes decide where they come within a margin (:mod:`cpr_kin.shapes.exact_pairs`).

    """

    urdf_path: Path
    model: Any
    collision_model: Any
    build_visual_model: Callable[[], Any] = field(repr=False)
    limits: JointLimits
    geometries: tuple[RobotGeometry, ...]
    _data: Any = field(repr=False)
    tcp_frame: str = "tcp"
    wrist_joints: tuple[str, ...] = ()
    position_ik: PositionIk | None = field(default=None, repr=False)
    limits_path: Path | None = None
    limits_defaulted: tuple[str, ...] = ()
    ranges_narrowed: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    held: Mapping[str, float] = field(default_factory=dict)
    base_joints: tuple[str, ...] = ()
    srdf_path: Path | None = None
    self_pairs: tuple[tuple[int, int], ...] = ()
    srdf_unknown_links: tuple[str, ...] = ()
    overlapping_links: tuple[tuple[str, str], ...] = ()
    close_pairs: tuple[ClosePair, ...] = ()
    massless_links: tuple[str, ...] = ()
    capsule_meshes: tuple[str, ...] = ()
    exact_meshes: Mapping[int, ExactMesh] = field(default_factory=dict)

    @cached_property
    def visual_model(self) -> Any:
        """Pinocchio geometry model of the visual shapes (class docstring)."""
        return self.build_visual_model()

    @cached_property
    def on_hulls(self) -> Robot:
        """The robot with its shapes deciding alone: no exact meshes (itself when it has none).

        One object per robot, so that what is computed once per robot (its reach, its self
        screens) is computed once for its hulls too, however many plans go on them.
        """
        return dataclasses.replace(self, exact_meshes={}) if self.exact_meshes else self

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
        """A Pinocchio ``Data`` of :attr:`model`, shared by this robot's own computations (one thread's).

        Plans run at once in threads of one process each need a robot of their own (as the batch's
        Dask workers load one per thread): a thread would read another's forward kinematics.
        """
        return self._data

    def check_links(self, names: Iterable[str], what: str) -> None:
        """Raise :class:`CprKinError` where ``names`` holds one that is no link of the robot.

        ``what`` says whose names they are (``"payload touch_links"``); the message lists the
        links with shapes (a typo would leave a pair checked, or excused, silently).
        """
        given = set(names)
        unknown = sorted(given - link_names(self.model)) if given else []
        if unknown:
            shaped = sorted({g.link for g in self.geometries if not g.carried})
            raise CprKinError(f"{what} {unknown} are not links of the robot; its links with shapes: {shaped}")

    def frame_id(self, frame: str) -> int:
        """Pinocchio id of ``frame``; raises :class:`CprKinError` naming the known frames."""
        index = frame_index(self.model, frame)
        if index < 0:
            known = sorted({f.name for f in self.model.frames})
            raise CprKinError(f"unknown frame '{frame}'; the robot's frames are {known}")
        return index

    def fixed_together(self, frame: str, other: str) -> bool:
        """Whether ``frame`` and ``other`` move as one: one joint carries both (fixed joints between them)."""
        frames = self.model.frames
        return bool(frames[self.frame_id(frame)].parentJoint == frames[self.frame_id(other)].parentJoint)

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
            held = sorted(set(values) & set(self.held))
            if held:
                raise JointLimitError(
                    f"joint(s) {held} are held (fixed), not planned; a map names the planned joints "
                    f"{list(self.joint_names)} (plan them with the robot's joints option)"
                )
            for name in values:
                self.limits.index(name)
            missing = [n for n in self.joint_names if n not in values]
            if missing:
                raise JointLimitError(
                    f"joint values {values} lack joint(s) {missing}; a map names every planned joint "
                    f"{list(self.joint_names)}"
                )
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
                f"joint vector {np.asarray(values).tolist()} has {q.size} value(s); expected {self.nq}, "
                f"one per planned joint {list(self.joint_names)} in this order (or a {{joint: value}} map)"
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
        return _unit(self.model.joints[self.limits.index(name) + 1])

    @property
    def joint_units(self) -> tuple[str, ...]:
        """``"rad"`` or ``"m"`` per planned joint, in configuration order (the model's joints)."""
        return joint_units(self.model)

    def group_geometries(self, group: str) -> Sequence[RobotGeometry]:
        """Geometries of collision group ``group`` (one of :data:`GROUPS`)."""
        if group not in GROUPS:
            raise CprKinError(f"unknown collision group '{group}'; allowed: {list(GROUPS)}")
        return [g for g in self.geometries if g.group == group]


def joint_units(model: Any) -> tuple[str, ...]:
    """``"rad"`` or ``"m"`` per joint of a Pinocchio ``model``."""
    return tuple(_unit(joint) for joint in model.joints[1:])


def _unit(joint: Any) -> str:
    """``"m"`` for a Pinocchio prismatic joint model, ``"rad"`` for any other."""
    return "m" if joint.shortname().removeprefix("JointModel").startswith("P") else "rad"
