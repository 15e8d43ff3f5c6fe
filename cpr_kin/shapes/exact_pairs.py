"""Geometry pairs measured on the robot's exact link meshes where their convex hulls are only bounds.

A concave link is checked as its convex hull, and where the hull exceeds the mesh by more than
:data:`cpr_kin.shapes.exact_meshes.REFINED_ABOVE_M` the mesh decides (:mod:`cpr_kin.shapes.exact_meshes`).
For a pair of such a link with another shape, with ``d_h`` coal's distance of the hulls (signed)
and ``e`` the pair's excess (its shapes' together), the meshes' distance ``d_x`` satisfies
``d_h <= d_x <= d_h + e``. So a margin test asks the meshes only where
``margin - e <= d_h < margin``; below that the pair is too close whatever the meshes, above it
clear. Every cheap bound of the hulls (:mod:`cpr_kin.bounds.pair_bounds`, :mod:`cpr_kin.bounds.reach`) bounds
the meshes too.

Where the hulls are apart, coal's distance of the meshes (triangle models) is ``d_x``, and a
margin test is coal's collision test of the meshes with the margin as security margin (its
distance, for a margin above :data:`COLLIDE_MARGIN_UP_TO_M`). Where
the hulls penetrate, the meshes may be apart: coal says so then, unless one holds the other
whole without their surfaces meeting, which is tested by winding number
(:meth:`cpr_kin.shapes.exact_meshes.ExactMesh.holds`): a point of the other shape (of a primitive or
convex shape, one; of a mesh, a vertex of every piece) inside the mesh. Where that cannot be
told (an obstacle of voxels or loose triangles, a mesh of many pieces), or the meshes meet, the
hulls' (negative) distance stands: the meshes' depth is not measured.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.common.arrays import distinct_sorted
from cpr_kin.shapes.coal_queries import as_transform, collide_margin_m
from cpr_kin.shapes.held_whole import inner_points, may_hold
from cpr_kin.shapes.mesh_pieces import Side, sides_apart

if TYPE_CHECKING:  # a robot with exact meshes imports them, and their vertices' witness
    from cpr_kin.shapes.exact_meshes import ExactMesh
    from cpr_kin.shapes.vertex_witness import VertexWitness

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

COLLIDE_MARGIN_UP_TO_M = 0.015
"""The largest margin [m] coal's collision test is asked with; a larger one goes to its distance
(:meth:`ExactPairs.closer_than`). Above the self margin a scene keeps by default (10 mm) plus the
search's step (1 mm): at 10 mm, each of those tests paid the collision test and the distance."""


class MeasuredApart(Protocol):
    """What a margin test remembers of the meshes' distances (as :mod:`cpr_kin.collision.clear_balls`)."""

    def clear(self, pair: int, q: FloatArray, margin_m: float) -> bool:
        """Whether pair ``pair`` surely keeps ``margin_m`` [m] at ``q``, by what was measured."""
        ...

    def add(self, pair: int, q: FloatArray, distance_m: float) -> None:
        """Keep that pair ``pair``'s meshes are ``distance_m`` [m] apart at ``q``."""
        ...


class ExactPairs:
    """The collision pairs of a geometry model, with the exact meshes of some of its geometries.

    Args:
        geometry_model: a geometry model whose first geometries are the robot's, pairs added.
        meshes: the robot's exact meshes by geometry index (:attr:`cpr_kin.Robot.exact_meshes`).
        measured: where :meth:`violated` keeps the meshes' distances it measures and asks them
            first (by default it keeps none, and asks coal's collision test).

    Attributes:
        excess_m: ``(P,)`` per collision pair, how far its distance on the shapes may be below
            its distance on the meshes [m] (0 where no mesh refines it).
        refined: ``(P,)`` the pairs with an exact mesh.
    """

    def __init__(
        self, geometry_model: Any, meshes: Mapping[int, ExactMesh], measured: MeasuredApart | None = None
    ) -> None:
        objects = geometry_model.geometryObjects
        self._pairs = [(int(p.first), int(p.second)) for p in geometry_model.collisionPairs]
        self._meshes = dict(meshes)
        self._shapes = [obj.geometry for obj in objects]
        self._inner = (
            [inner_points(obj.geometry, self._meshes.get(g)) for g, obj in enumerate(objects)]
            if meshes
            else []
        )
        excess = {g: mesh.excess_m for g, mesh in self._meshes.items()}
        self.excess_m = np.array([excess.get(a, 0.0) + excess.get(b, 0.0) for a, b in self._pairs])
        self.refined = np.array([a in excess or b in excess for a, b in self._pairs], dtype=bool)
        self.excess_m.setflags(write=False)
        self.refined.setflags(write=False)
        self._excess, self._refined = self.excess_m.tolist(), self.refined.tolist()  # for the loops
        self._witness: VertexWitness | None = None
        if meshes:
            from cpr_kin.shapes.vertex_witness import VertexWitness

            self._witness = VertexWitness(self._shapes, self._meshes)
        self._request = coal.DistanceRequest()
        self._collision = coal.CollisionRequest()
        self._collision.enable_contact = False
        self._measured = measured

    def __bool__(self) -> bool:
        return bool(self.refined.any())

    def may_be_closest(self, hull_m: FloatArray, group: NDArray[np.int64]) -> BoolArray:
        """``(P,)`` the refined pairs whose mesh distance may be the smallest of their ``group``.

        ``hull_m`` ``(P,)`` the pairs' hull distances [m]: a pair's mesh distance is at most its
        hull distance plus its excess, so one whose hull distance is above that for another
        pair of its group cannot be the group's closest.
        """
        ceiling = np.full(len(hull_m), np.inf)
        for g in distinct_sorted(group).tolist():  # np.unique would import numpy.ma into a new process
            members = group == g
            ceiling[members] = np.min(hull_m[members] + self.excess_m[members])
        return np.asarray(self.refined & (hull_m < ceiling))

    def distance(self, geometry_data: Any, pair: int, hull_m: float) -> float:
        """Pair ``pair``'s distance [m] on the meshes, placed in ``geometry_data``, hulls ``hull_m`` apart."""
        found = self.measured(geometry_data, pair, hull_m)
        return hull_m if found is None else max(float(found.min_distance), hull_m)

    def settled(
        self, geometry_data: Any, pair: int, hull_m: float, ceiling_m: float, below_m: float
    ) -> float:
        """Pair ``pair``'s distance [m] as a search for the closest pair needs it, its hulls ``hull_m`` apart.

        Exact on the meshes where it is below ``ceiling_m`` and ``below_m`` is infinite; at least
        ``ceiling_m`` where the meshes are that far apart (coal's collision test); where
        ``below_m`` is finite and the meshes are nearer than it, the hulls' distance (the
        pair is below it; its depth is not measured). The cheapest query that answers.
        """
        finite = np.isfinite(below_m)
        if finite and hull_m + self.excess_m[pair] < below_m:
            return hull_m  # the meshes cannot reach below_m: below it for sure
        if np.isfinite(ceiling_m):  # coal's test takes no negative margin: apart is at least as far
            if not self.closer_than(geometry_data, pair, hull_m, max(ceiling_m, 0.0)):
                return max(hull_m, ceiling_m)
            if finite:
                return hull_m
        return self.distance(geometry_data, pair, hull_m)

    def measured(self, geometry_data: Any, pair: int, hull_m: float) -> Any:
        """The ``coal.DistanceResult`` of pair ``pair`` on the meshes, ``None`` where the hulls' stands.

        The shapes are placed as in ``geometry_data``, ``hull_m`` apart [m] (module docstring).
        """
        a, b = self._pairs[pair]
        (shape_a, at_a), (shape_b, at_b) = self._placed(geometry_data, a), self._placed(geometry_data, b)
        result = self._distance(shape_a, as_transform(at_a), shape_b, as_transform(at_b))
        if hull_m >= 0.0:
            return result
        if result.min_distance <= 0.0 or self._one_holds_other(a, at_a, b, at_b):
            return None
        return result

    def closer_than(
        self, geometry_data: Any, pair: int, hull_m: float, margin_m: float, q: FloatArray | None = None
    ) -> bool:
        """Whether pair ``pair`` is within ``margin_m`` >= 0 [m] on its meshes, hulls ``hull_m`` apart.

        coal's collision test with the margin as security margin descends into every pair of
        bounding volumes within the margin: fast for a margin of millimetres, where it stops at
        the first pair of triangles within it; for a margin near a link's size (dense meshes a
        few centimetres apart), seconds. So the test takes a margin up to
        :data:`COLLIDE_MARGIN_UP_TO_M`, and above it coal's distance decides, which prunes by the
        nearest pair found so far. Where one side is a mesh and the other a primitive, a vertex
        of the mesh within the margin of it answers first (:mod:`cpr_kin.shapes.vertex_witness`:
        where the mesh wraps the primitive, coal's descent takes milliseconds), then the meshes'
        convex pieces (:mod:`cpr_kin.shapes.mesh_pieces`: where they keep the margin, so do the
        meshes). Given the configuration ``q`` and a memory (``measured``), it is asked first,
        and coal's distance decides instead of its collision test (a distance the memory keeps).
        """
        memory = self._measured if q is not None else None
        least_m = float(collide_margin_m(margin_m))  # the least margin coal's test is asked
        asked_m = least_m if memory is not None else margin_m
        if memory is not None and q is not None and memory.clear(pair, q, asked_m):
            return False
        a, b = self._pairs[pair]
        (shape_a, at_a), (shape_b, at_b) = self._placed(geometry_data, a), self._placed(geometry_data, b)
        if self._witness is not None and self._witness.proves(a, at_a, b, at_b, margin_m):
            return True
        placed = (shape_a, as_transform(at_a), shape_b, as_transform(at_b))
        sides = self._side(geometry_data, a, placed[1]), self._side(geometry_data, b, placed[3])
        apart_m = sides_apart(*sides, least_m)
        if apart_m is not None:  # every triangle lies in a piece that keeps the margin
            distance_m, hit = apart_m, False
        elif memory is not None:
            distance_m = float(self._distance(*placed).min_distance)
            hit = distance_m < asked_m
        else:
            self._collision.security_margin = float(collide_margin_m(min(margin_m, COLLIDE_MARGIN_UP_TO_M)))
            hit = coal.collide(*placed, self._collision, coal.CollisionResult())
            if not hit and margin_m > COLLIDE_MARGIN_UP_TO_M:
                hit = self._distance(*placed).min_distance < margin_m
        if hit or (hull_m < 0.0 and self._one_holds_other(a, at_a, b, at_b)):
            return True
        if memory is not None and q is not None:
            memory.add(pair, q, distance_m)
        return False

    def recheck(
        self,
        flagged: BoolArray,
        model: Any,
        data: Any,
        geometry_model: Any,
        geometry_data: Any,
        batch: FloatArray,
        active: IntArray,
        margins_m: FloatArray,
        ordered: bool = False,
    ) -> BoolArray:
        """``flagged`` ``(N,)``, what a margin test on the hulls flagged at ``batch``, decided again.

        Where some of the ``active`` pairs has a mesh, each flagged configuration is decided by
        :meth:`violated` (``margins_m`` ``(P,)`` per collision pair [m]); elsewhere the hulls' answer
        stands. With ``ordered``, up to the first configuration found violated, those after it
        reported violated without a test. Updated in place and returned.
        """
        if flagged.any() and self.refined[active].any():
            rows = np.flatnonzero(flagged)
            flagged[rows] = self.violated(
                model, data, geometry_model, geometry_data, batch[rows], active.tolist(), margins_m, ordered
            )
        return flagged

    def violated(
        self,
        model: Any,
        data: Any,
        geometry_model: Any,
        geometry_data: Any,
        batch: FloatArray,
        pairs: Sequence[int],
        margins_m: float | FloatArray,
        ordered: bool = False,
    ) -> BoolArray:
        """``(N,)`` whether some of ``pairs`` is closer than its margin at configurations ``batch``.

        With ``ordered``, the configurations are decided in order up to the first violated one;
        those after it are reported violated without a test (what an edge check needs).

        ``margins_m`` [m]: one margin for every pair, or ``(P,)`` one per collision pair. The
        pairs without a mesh are asked first; a pair with one goes to its meshes only in its
        margin's band (module docstring). A configuration's pairs are measured one at a time,
        up to the first closer than its margin: where the hulls flagged it, that is most often
        one of the first (``docs/tuning.md``, Exact meshes).
        """
        excess, refined = self._excess, self._refined
        order = sorted(pairs, key=refined.__getitem__)
        given = np.asarray(margins_m, dtype=float)
        margins = np.broadcast_to(given, len(excess)).tolist() if given.ndim else [float(given)] * len(excess)
        found = np.zeros(len(batch), dtype=bool)
        for row, q in enumerate(batch):
            pin.updateGeometryPlacements(model, data, geometry_model, geometry_data, q)
            for p in order:
                hull = pin.computeDistance(geometry_model, geometry_data, p).min_distance
                if hull >= margins[p]:
                    continue
                if (
                    not refined[p]
                    or hull + excess[p] < margins[p]
                    or self.closer_than(geometry_data, p, hull, margins[p], q)
                ):
                    found[row] = True
                    break
            if ordered and found[row]:
                found[row:] = True
                break
        return found

    def _distance(self, shape_a: Any, at_a: Any, shape_b: Any, at_b: Any) -> Any:
        """The ``coal.DistanceResult`` of two shapes at their ``coal.Transform3s`` placements."""
        result = coal.DistanceResult()
        coal.distance(shape_a, at_a, shape_b, at_b, self._request, result)
        return result

    def _placed(self, geometry_data: Any, geometry: int) -> tuple[Any, Any]:
        """The geometry's decisive shape (its mesh, if it has one) and its placement in the world."""
        placement = geometry_data.oMg[geometry]
        mesh = self._meshes.get(geometry)
        if mesh is None:
            return self._shapes[geometry], placement
        return mesh.bvh, placement * mesh.mesh_in_shape

    def _side(self, geometry_data: Any, geometry: int, at: Any) -> Side:
        """The geometry's convex pieces at ``at`` (its mesh's, else its shape) and its own shape, placed."""
        mesh, shape = self._meshes.get(geometry), self._shapes[geometry]
        return Side((shape,) if mesh is None else mesh.pieces, at, shape, geometry_data.oMg[geometry])

    def _one_holds_other(self, a: int, at_a: Any, b: int, at_b: Any) -> bool:
        """Whether ``a``'s mesh may hold ``b`` whole or ``b``'s ``a`` (:mod:`cpr_kin.shapes.held_whole`)."""
        meshes, inner = self._meshes, self._inner
        return may_hold(meshes.get(a), inner[b], at_a, at_b) or may_hold(meshes.get(b), inner[a], at_b, at_a)
