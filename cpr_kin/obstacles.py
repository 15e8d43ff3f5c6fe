"""Static obstacles as coal geometries with a pose in the world frame."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.errors import ObstacleError

FloatArray = NDArray[np.float64]

Shape = Literal["box", "sphere", "cylinder", "capsule", "mesh"]
SHAPES: tuple[str, ...] = ("box", "sphere", "cylinder", "capsule", "mesh")
"""Supported obstacle shapes."""


def _vector(value: ArrayLike, what: str, n: int) -> FloatArray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise ObstacleError(f"{what} = {value!r} must be {n} numbers") from None
    if arr.shape != (n,):
        raise ObstacleError(
            f"{what} = {np.asarray(value).tolist()} must have {n} values, not shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        raise ObstacleError(f"{what} = {arr.tolist()} must be finite numbers (no NaN or inf)")
    arr.setflags(write=False)
    return arr


def _positive(value: float | None, what: str) -> float:
    if value is None:
        raise ObstacleError(f"{what} is required")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise ObstacleError(f"{what} = {value!r} must be a number > 0 [m]") from None
    if not (math.isfinite(x) and x > 0.0):
        raise ObstacleError(f"{what} = {x} must be a finite number > 0 [m]")
    return x


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
      safe side; with ``convex = False`` the triangle surface, whose inside coal cannot see.

    Use the constructors :meth:`box`, :meth:`sphere`, :meth:`cylinder`, :meth:`capsule` and
    :meth:`from_mesh`; every value is validated on construction.

    Attributes:
        shape: one of :data:`SHAPES`.
        xyz: position of the shape's centre in the world [m].
        rpy: orientation as roll, pitch, yaw about fixed x, y, z axes [rad].
        name: a name for messages and displays.

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

    def __post_init__(self) -> None:
        if self.shape not in SHAPES:
            raise ObstacleError(
                f"obstacle '{self.name}': unknown shape {self.shape!r}; allowed: {list(SHAPES)}"
            )
        object.__setattr__(self, "xyz", _vector(self.xyz, f"obstacle '{self.name}' xyz", 3))
        object.__setattr__(self, "rpy", _vector(self.rpy, f"obstacle '{self.name}' rpy", 3))
        if self.shape == "box":
            size = _vector(self.size if self.size is not None else [], f"obstacle '{self.name}' size", 3)
            if not np.all(size > 0):
                raise ObstacleError(
                    f"obstacle '{self.name}' size = {size.tolist()} must be > 0 in every axis [m]"
                )
            object.__setattr__(self, "size", size)
        if self.shape in ("sphere", "cylinder", "capsule"):
            object.__setattr__(self, "radius", _positive(self.radius, f"obstacle '{self.name}' radius"))
        if self.shape in ("cylinder", "capsule"):
            object.__setattr__(self, "length", _positive(self.length, f"obstacle '{self.name}' length"))
        if self.shape == "mesh":
            if self.mesh is None or not Path(self.mesh).is_file():
                raise ObstacleError(f"obstacle '{self.name}': mesh file '{self.mesh}' does not exist")
            object.__setattr__(self, "mesh", Path(self.mesh))
            object.__setattr__(self, "scale", _positive(self.scale, f"obstacle '{self.name}' scale"))

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
        rotation = pin.rpy.rpyToMatrix(*self.rpy)
        return pin.SE3(rotation, np.array(self.xyz))

    def geometry(self) -> Any:
        """A new coal collision geometry of this obstacle in its local frame."""
        if self.shape == "box":
            return coal.Box(*(float(x) for x in np.asarray(self.size)))
        if self.shape == "sphere":
            return coal.Sphere(self.radius)
        if self.shape == "cylinder":
            return coal.Cylinder(self.radius, self.length)
        if self.shape == "capsule":
            return coal.Capsule(self.radius, self.length)
        return self._mesh_geometry()

    def _mesh_geometry(self) -> Any:
        import trimesh  # only needed for mesh obstacles

        try:
            mesh: Any = trimesh.load(str(self.mesh), force="mesh")
        except Exception as exc:  # trimesh raises many types for unreadable files
            raise ObstacleError(f"obstacle '{self.name}': cannot read mesh '{self.mesh}': {exc}") from None
        if len(mesh.faces) == 0:
            raise ObstacleError(f"obstacle '{self.name}': mesh '{self.mesh}' has no triangles")
        if self.convex:
            mesh = mesh.convex_hull
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(mesh.faces), len(mesh.vertices))
        bvh.addVertices(np.asarray(mesh.vertices, dtype=np.float64) * self.scale)
        bvh.addTriangles(np.asarray(mesh.faces, dtype=np.int64))
        bvh.endModel()
        if self.convex:
            bvh.buildConvexRepresentation(False)
            return bvh.convex
        return bvh
