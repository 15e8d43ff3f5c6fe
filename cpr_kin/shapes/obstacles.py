"""Static obstacles as coal geometries with a pose in the world frame."""

from __future__ import annotations

import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import CprKinError, ObstacleError
from cpr_kin.common.names import shown, unprintable
from cpr_kin.common.user_files import UserFileError, read_bytes
from cpr_kin.shapes.obstacle_ranges import (
    MAX_ANGLE_RAD,
    MAX_COORDINATE_M,
    MAX_MESH_BYTES,
    MAX_NAME_CHARS,
    SCALE_RANGE,
    SIZE_RANGE_M,
)

FloatArray = NDArray[np.float64]

Shape = Literal["box", "sphere", "cylinder", "capsule", "mesh", "voxels"]
SHAPES: tuple[str, ...] = ("box", "sphere", "cylinder", "capsule", "mesh", "voxels")
"""Supported obstacle shapes."""


def _shown(value: object) -> str:
    """:func:`~cpr_kin.common.names.shown` of a value, an array as a list."""
    return shown(value.tolist() if isinstance(value, np.ndarray) else value)


def _vector(value: ArrayLike, what: str, n: int, low: float, high: float, unit: str) -> FloatArray:
    try:
        if np.asarray(value).dtype == np.bool_:
            raise TypeError("booleans are not coordinates")
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ObstacleError(f"{what} = {_shown(value)} must be {n} numbers") from None
    if arr.shape != (n,):
        raise ObstacleError(f"{what} = {_shown(value)} must have {n} values, not shape {arr.shape}")
    if not np.all(np.isfinite(arr) & (arr >= low) & (arr <= high)):
        raise ObstacleError(
            f"{what} = {_shown(arr.tolist())} must be finite numbers in [{low:g}, {high:g}] {unit}"
        )
    arr.setflags(write=False)
    return arr


def _number(value: float | None, what: str, low: float, high: float, unit: str) -> float:
    if value is None:
        raise ObstacleError(f"{what} is required")
    if isinstance(value, bool | np.bool_):  # Python's True is 1, but not a size
        raise ObstacleError(f"{what} = {value} must be a number in [{low:g}, {high:g}] {unit}".rstrip())
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ObstacleError(
            f"{what} = {_shown(value)} must be a number in [{low:g}, {high:g}] {unit}".rstrip()
        ) from None
    if not (math.isfinite(x) and low <= x <= high):
        raise ObstacleError(f"{what} = {x:g} must be a number in [{low:g}, {high:g}] {unit}".rstrip())
    return x


def placement(xyz: ArrayLike, rpy: ArrayLike) -> Any:
    """The ``pinocchio.SE3`` of a frame at ``xyz`` [m], turned by ``rpy`` about fixed x, y, z [rad]."""
    import pinocchio as pin  # imported when geometry is built: reading a scene needs neither

    return pin.SE3(pin.rpy.rpyToMatrix(*np.asarray(rpy, dtype=float)), np.array(xyz, dtype=float))


@dataclass(frozen=True, eq=False)
class Obstacle:
    """A static obstacle: a shape, its dimensions and its pose in the world frame.

    Shapes and their dimensions (all [m]):

    - ``box``: ``size = (x, y, z)`` full side lengths, centred on the pose;
    - ``sphere``: ``radius``;
    - ``cylinder``: ``radius``, ``length`` along the local z axis, centred on the pose;
    - ``capsule``: ``radius``, ``length`` of the axis segment (local z), centred;
    - ``mesh``: ``mesh`` file (any format trimesh reads), ``scale``; with ``convex = True``
      (the default) its convex hull is used, which gives a signed distance and errs on the
      safe side; with ``convex = False`` the triangle surface, whose inside coal cannot see;
    - ``voxels``: ``points``, the centres of the occupied cubes of side ``resolution`` (a
      point cloud's, :mod:`cpr_kin.shapes.point_clouds`), in the obstacle's frame, a coal OcTree.

    Use the constructors :meth:`box`, :meth:`sphere`, :meth:`cylinder`, :meth:`capsule` and
    :meth:`from_mesh`; every value is validated on construction.

    Attributes:
        shape: one of :data:`SHAPES`.
        xyz: position of the shape's centre in the world [m].
        rpy: orientation as roll, pitch, yaw about fixed x, y, z axes [rad].
        name: a name for messages and displays.
        touch_links: links of the robot that may touch it (a gripper's fingers at a part it
            grasps or leaves, MoveIt's allowed contacts of a world object): their pairs with
            it are not checked. What the robot carries is checked against it all the same
            (unless its payload's ``touch_obstacles`` name it).

    """

    shape: Shape
    xyz: FloatArray
    rpy: FloatArray = field(default_factory=lambda: np.zeros(3))
    name: str = "obstacle"
    size: FloatArray | None = None
    radius: float | None = None
    length: float | None = None
    mesh: Path | None = None
    scale: float = 1.0
    convex: bool = True
    points: FloatArray | None = None
    resolution: float | None = None
    touch_links: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise ObstacleError(
                f"obstacle '{self.name}': unknown shape {self.shape!r}; allowed: {list(SHAPES)}"
            )
        if not isinstance(self.name, str) or not 0 < len(self.name) <= MAX_NAME_CHARS:
            raise ObstacleError(f"obstacle name {_shown(self.name)} must be 1 to {MAX_NAME_CHARS} characters")
        character = unprintable(self.name)
        if character is not None:
            raise ObstacleError(
                f"obstacle name {_shown(self.name)} holds {character}; names must be printable text"
            )
        what = f"obstacle '{self.name}'"
        links = self.touch_links
        if isinstance(links, str) or not all(isinstance(n, str) and unprintable(n) is None for n in links):
            raise ObstacleError(f"{what} touch_links = {_shown(links)} must be a sequence of link names")
        object.__setattr__(self, "touch_links", tuple(links))
        bound = MAX_COORDINATE_M
        object.__setattr__(self, "xyz", _vector(self.xyz, f"{what} xyz", 3, -bound, bound, "m"))
        object.__setattr__(
            self, "rpy", _vector(self.rpy, f"{what} rpy", 3, -MAX_ANGLE_RAD, MAX_ANGLE_RAD, "rad")
        )
        if self.shape == "box":
            size: ArrayLike = [] if self.size is None else self.size
            object.__setattr__(self, "size", _vector(size, f"{what} size", 3, *SIZE_RANGE_M, "m"))
        if self.shape in ("sphere", "cylinder", "capsule"):
            object.__setattr__(self, "radius", _number(self.radius, f"{what} radius", *SIZE_RANGE_M, "m"))
        if self.shape in ("cylinder", "capsule"):
            object.__setattr__(self, "length", _number(self.length, f"{what} length", *SIZE_RANGE_M, "m"))
        if self.shape == "voxels":
            from cpr_kin.shapes.point_clouds import checked_voxels

            points, resolution = checked_voxels(self.points, self.resolution, what)
            object.__setattr__(self, "points", points)
            object.__setattr__(self, "resolution", resolution)
        if self.shape == "mesh":
            if self.mesh is None:
                raise ObstacleError(f"{what}: a mesh obstacle needs a mesh file")
            mesh = Path(self.mesh)
            if not mesh.is_file() or mesh.stat().st_size > MAX_MESH_BYTES:
                try:  # the same words as for every other file a user gives
                    read_bytes(mesh, MAX_MESH_BYTES, f"{what}: mesh file")
                except UserFileError as exc:
                    raise ObstacleError(str(exc)) from None
            object.__setattr__(self, "mesh", mesh)
            object.__setattr__(self, "scale", _number(self.scale, f"{what} scale", *SCALE_RANGE, ""))

    def _key(self) -> tuple[object, ...]:
        size = None if self.size is None else tuple(np.asarray(self.size).tolist())
        return (
            self.shape,
            self.name,
            tuple(self.xyz.tolist()),
            tuple(self.rpy.tolist()),
            size,
            self.radius,
            self.length,
            None if self.mesh is None else str(self.mesh),
            self.scale,
            self.convex,
            None if self.points is None else hash(np.asarray(self.points).tobytes()),
            self.resolution,
            self.touch_links,
        )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Obstacle):
            return NotImplemented
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    @classmethod
    def box(cls, size: ArrayLike, xyz: ArrayLike, rpy: ArrayLike = (0, 0, 0), name: str = "box") -> Obstacle:
        """A box of full side lengths ``size`` [m] centred at ``xyz``."""
        return cls(
            shape="box",
            size=np.asarray(size, dtype=float),
            xyz=np.asarray(xyz),
            rpy=np.asarray(rpy),
            name=name,
        )

    @classmethod
    def sphere(cls, radius: float, xyz: ArrayLike, name: str = "sphere") -> Obstacle:
        """A sphere of ``radius`` [m] centred at ``xyz``."""
        return cls(shape="sphere", radius=radius, xyz=np.asarray(xyz), name=name)

    @classmethod
    def cylinder(
        cls, radius: float, length: float, xyz: ArrayLike, rpy: ArrayLike = (0, 0, 0), name: str = "cylinder"
    ) -> Obstacle:
        """A cylinder of ``radius`` and ``length`` [m] along its local z, centred at ``xyz``."""
        return cls(
            shape="cylinder",
            radius=radius,
            length=length,
            xyz=np.asarray(xyz),
            rpy=np.asarray(rpy),
            name=name,
        )

    @classmethod
    def capsule(
        cls, radius: float, length: float, xyz: ArrayLike, rpy: ArrayLike = (0, 0, 0), name: str = "capsule"
    ) -> Obstacle:
        """A capsule: segment of ``length`` [m] along local z swept by a ball of ``radius``."""
        return cls(
            shape="capsule", radius=radius, length=length, xyz=np.asarray(xyz), rpy=np.asarray(rpy), name=name
        )

    @classmethod
    def from_mesh(
        cls,
        path: str | Path,
        xyz: ArrayLike,
        rpy: ArrayLike = (0, 0, 0),
        scale: float = 1.0,
        convex: bool = True,
        name: str = "mesh",
    ) -> Obstacle:
        """A mesh file (STL, OBJ, PLY, ... through trimesh), scaled by ``scale``."""
        return cls(
            shape="mesh",
            mesh=Path(path),
            scale=scale,
            convex=convex,
            xyz=np.asarray(xyz),
            rpy=np.asarray(rpy),
            name=name,
        )

    @property
    def placement(self) -> Any:
        """Pose ``obstacle_in_world`` as a ``pinocchio.SE3``."""
        return placement(self.xyz, self.rpy)

    def geometry(self) -> Any:
        """A new coal collision geometry of this obstacle in its local frame."""
        import coal  # imported when geometry is built: reading a scene needs neither

        if self.shape == "box":
            return coal.Box(*(float(x) for x in np.asarray(self.size)))
        if self.shape == "sphere":
            return coal.Sphere(self.radius)
        if self.shape == "cylinder":
            return coal.Cylinder(self.radius, self.length)
        if self.shape == "capsule":
            return coal.Capsule(self.radius, self.length)
        if self.shape == "voxels":
            from cpr_kin.shapes.point_clouds import voxel_geometry

            return voxel_geometry(np.asarray(self.points), float(self.resolution or 0.0))
        from cpr_kin.shapes.mesh_geometry import mesh_geometry

        return mesh_geometry(Path(str(self.mesh)), float(self.scale), self.convex, self.name)


def checked_obstacles(obstacles: Sequence[Obstacle]) -> tuple[Obstacle, ...]:
    """``obstacles`` as a tuple, each an :class:`Obstacle` and each name once.

    Raises:
        CprKinError: an item that is no obstacle (names or dicts, which fail deep inside), or
            a name given twice.
    """
    strangers = [type(o).__name__ for o in obstacles if not isinstance(o, Obstacle)]
    if strangers:
        raise CprKinError(
            f"obstacles hold {len(strangers)} item(s) that are not cpr_kin.Obstacle "
            f"(a {strangers[0]}); make them with Obstacle.box, .sphere, .cylinder, ..."
        )
    duplicated = sorted(n for n, count in Counter(o.name for o in obstacles).items() if count > 1)
    if duplicated:
        raise CprKinError(f"obstacle names must be unique; {duplicated} appear more than once")
    return tuple(obstacles)
