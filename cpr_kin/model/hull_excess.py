"""How far each collision shape of a robot reaches beyond the link mesh it stands for.

A link's mesh is checked as its convex hull (:func:`cpr_kin.description.urdf_models.convex_hulls`): it
contains the mesh, so a configuration it accepts is clear, but a concave link's hull fills its
hollows and refuses what the mesh would allow. Where a hull exceeds its mesh by more than
:data:`cpr_kin.shapes.exact_meshes.REFINED_ABOVE_M`, the mesh itself decides
(:mod:`cpr_kin.shapes.exact_pairs`) and the model's excess there is 0; the hull's is reported beside
it. The excess of a shape is the largest distance from a point of its surface to the mesh:
:data:`SAMPLES` points drawn on the hull's surface by area (trimesh, seeded), each measured by
coal to the mesh's triangles as coal's loader reads them (the same file and scale the hull was
built from). A distance moves by at most as much as the point does, so the sampled largest is
below the true one by at most the spacing of the samples (reported: the side of a square of
the surface's area over the count).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from cpr_kin.model.robot import Robot
from cpr_kin.shapes.exact_meshes import MeshSource, hull_excess

SAMPLES = 20_000
"""Points drawn on each hull's surface."""


@dataclass(frozen=True)
class ShapeExcess:
    """One collision shape beside the mesh it stands for.

    Attributes:
        geometry: the collision geometry's name.
        link: its link.
        kind: ``"exact mesh"`` (the mesh decides, its hull or capsule a bound), ``"convex
            hull"`` of a mesh, or the URDF's primitive (``"box"``, ``"cylinder"``, ...: exact).
        mesh: the mesh file, or ``""`` for a primitive.
        excess_m: the largest distance of the model's surface from the mesh [m], sampled; 0
            for a primitive and an exact mesh.
        spacing_m: how far below the true largest the sampled one may be [m].
        bound_excess_m: an exact mesh's bounding shape's excess [m] (NaN for a bounding
            capsule, :attr:`cpr_kin.Robot.capsule_meshes`, not measured); else equal to ``excess_m``.
    """

    geometry: str
    link: str
    kind: str
    mesh: str
    excess_m: float
    spacing_m: float = 0.0
    bound_excess_m: float = 0.0


def shape_excess(robot: Robot, samples: int = SAMPLES, seed: int = 0) -> tuple[ShapeExcess, ...]:
    """The excess of each of ``robot``'s collision shapes (module docstring), in geometry order."""
    import coal
    import pinocchio as pin

    loader = coal.MeshLoader()
    found = []
    for geometry in robot.geometries:
        obj = robot.collision_model.geometryObjects[geometry.index]
        kind = type(obj.geometry).__name__.lower()
        exact = geometry.index in robot.exact_meshes
        if geometry.name in robot.capsule_meshes:
            found.append(
                ShapeExcess(geometry.name, geometry.link, "exact mesh", obj.meshPath, 0.0, 0.0, math.nan)
            )
            continue
        if kind != "convex" or not obj.meshPath:
            found.append(ShapeExcess(geometry.name, geometry.link, kind, "", 0.0))
            continue
        scale = tuple(float(s) for s in obj.meshScale)
        mesh = loader.load(obj.meshPath, np.asarray(scale))
        source = MeshSource(geometry.index, mesh, pin.SE3.Identity(), obj.meshPath, scale)
        measured = hull_excess(source, samples, seed)
        hull_m, spacing_m = measured["excess_m"], measured["spacing_m"]
        kind = "exact mesh" if exact else "convex hull"
        found.append(
            ShapeExcess(
                geometry.name, geometry.link, kind, obj.meshPath, 0.0 if exact else hull_m, spacing_m, hull_m
            )
        )
    return tuple(found)
