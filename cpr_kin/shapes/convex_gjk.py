"""A margin test of two convex shapes by GJK, compiled, deciding only where its bounds are certain.

Gilbert, Johnson and Keerthi's algorithm (1988) walks a simplex inside the Minkowski
difference ``C = A - B`` of two convex shapes towards the origin. At its point ``v`` of ``C``
closest to the origin so far, and the support point ``w`` of ``C`` in the direction ``-v``,
the distance ``d`` between the shapes is bounded on both sides:

- ``d <= |v|``, since ``v`` lies in ``C`` (a convex combination of its points);
- ``d >= v . w / |v|``, since every point ``p`` of ``C`` has ``p . v >= w . v``.

A margin test ``d < m`` needs no more than those bounds: :func:`margin_state` returns
:data:`HIT` once ``|v|`` is below ``m`` less a band, :data:`CLEAR` once the lower bound is
above ``m`` plus the band, and :data:`UNSURE` where neither comes (a distance within the band
of the margin, a degenerate simplex, the iteration limit): the caller asks coal there. So the
answer, where there is one, is coal's wherever coal is right to its error, and never a guess.

Shapes (:data:`CONVEX`, :data:`BOX`, :data:`SPHERE`, :data:`CAPSULE`, :data:`CYLINDER`) are
cores (vertices, a box, a point, a segment, a cylinder) swept by a radius: the test runs on
the cores, its margin grown by both radii. The closest point of a simplex is Ericson's
("Real-Time Collision Detection", 2005, 5.1.5-5.1.6): a triangle's Voronoi regions, a
tetrahedron's faces that see the origin.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

UNSUPPORTED, CONVEX, BOX, SPHERE, CAPSULE, CYLINDER = -1, 0, 1, 2, 3, 4
"""A shape's kind: its core's support function (:func:`support`)."""
CLEAR, HIT, UNSURE = 0, 1, 2
"""A margin test's answer: farther than the margin, closer, or within the band (coal decides)."""
MAX_ITERATIONS = 64
"""GJK's iterations before :data:`UNSURE`: more than a test of a robot's hulls takes to decide
(each iteration adds a vertex of the difference, and the pair's last direction starts it)."""
FACES = np.array([[0, 1, 2, 3], [0, 2, 3, 1], [0, 3, 1, 2], [1, 3, 2, 0]], dtype=np.int64)
"""A tetrahedron's faces (three vertices) and the vertex opposite each."""
CONVERGED = 1e-12
"""Relative progress ``(|v|^2 - v.w) / |v|^2`` below which GJK has converged without a verdict."""
Cores = tuple[IntArray, FloatArray, IntArray, FloatArray]
"""The shapes' cores as :func:`support` reads them: ``(kinds, half, first, vertices)``, each
geometry's kind ``(G,)``, a box's half sides or a capsule's or cylinder's ``(r, h, 0)`` ``(G, 3)``
[m], where each convex shape's vertices begin ``(G + 1,)``, and those vertices ``(V, 3)``
[m] (:class:`~cpr_kin.shapes.gjk_shapes.GeometryShapes`)."""


@njit
def support(
    g: int, cores: Cores, rotation: FloatArray, translation: FloatArray, dx: float, dy: float, dz: float
) -> tuple[float, float, float]:
    """The point of shape ``g``'s core farthest along the world direction ``(dx, dy, dz)``, in the world.

    ``rotation[g]`` ``(3, 3)`` and ``translation[g]`` ``(3,)`` [m] place the shape; ``cores``
    (:data:`Cores`) holds its kind and its box's, segment's or vertices' dimensions.
    """
    kinds, half, first, vertices = cores
    lx = rotation[g, 0, 0] * dx + rotation[g, 1, 0] * dy + rotation[g, 2, 0] * dz
    ly = rotation[g, 0, 1] * dx + rotation[g, 1, 1] * dy + rotation[g, 2, 1] * dz
    lz = rotation[g, 0, 2] * dx + rotation[g, 1, 2] * dy + rotation[g, 2, 2] * dz
    kind = kinds[g]
    px = py = pz = 0.0
    if kind == CONVEX:
        best = -math.inf
        for k in range(first[g], first[g + 1]):
            along = vertices[k, 0] * lx + vertices[k, 1] * ly + vertices[k, 2] * lz
            if along > best:
                best, px, py, pz = along, vertices[k, 0], vertices[k, 1], vertices[k, 2]
    elif kind == BOX:
        px = half[g, 0] if lx >= 0.0 else -half[g, 0]
        py = half[g, 1] if ly >= 0.0 else -half[g, 1]
        pz = half[g, 2] if lz >= 0.0 else -half[g, 2]
    elif kind == CAPSULE:
        pz = half[g, 1] if lz >= 0.0 else -half[g, 1]
    elif kind == CYLINDER:
        across = math.sqrt(lx * lx + ly * ly)
        if across > 0.0:
            px, py = half[g, 0] * lx / across, half[g, 0] * ly / across
        pz = half[g, 1] if lz >= 0.0 else -half[g, 1]
    wx = translation[g, 0] + rotation[g, 0, 0] * px + rotation[g, 0, 1] * py + rotation[g, 0, 2] * pz
    wy = translation[g, 1] + rotation[g, 1, 0] * px + rotation[g, 1, 1] * py + rotation[g, 1, 2] * pz
    wz = translation[g, 2] + rotation[g, 2, 0] * px + rotation[g, 2, 1] * py + rotation[g, 2, 2] * pz
    return wx, wy, wz


@njit
def _edges_towards_origin(simplex: FloatArray, i: int, j: int, k: int, vertex: int) -> tuple[float, float]:
    """``(b - a) . (0 - p)`` and ``(c - a) . (0 - p)``, ``a, b, c`` and ``p``: ``simplex[i, j, k, vertex]``.

    How far along each edge of the triangle from ``a`` the origin lies from its vertex ``p``.
    """
    a, p = simplex[i], simplex[vertex]
    along_b = (simplex[j, 0] - a[0]) * p[0] + (simplex[j, 1] - a[1]) * p[1] + (simplex[j, 2] - a[2]) * p[2]
    along_c = (simplex[k, 0] - a[0]) * p[0] + (simplex[k, 1] - a[1]) * p[1] + (simplex[k, 2] - a[2]) * p[2]
    return -along_b, -along_c


@njit
def closest_on_triangle(simplex: FloatArray, i: int, j: int, k: int) -> tuple[float, float, float]:
    """Barycentric weights of the origin's closest point on triangle ``simplex[i], [j], [k]`` (Ericson)."""
    d1, d2 = _edges_towards_origin(simplex, i, j, k, i)
    if d1 <= 0.0 and d2 <= 0.0:
        return 1.0, 0.0, 0.0
    d3, d4 = _edges_towards_origin(simplex, i, j, k, j)
    if d3 >= 0.0 and d4 <= d3:
        return 0.0, 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        t = d1 / (d1 - d3)
        return 1.0 - t, t, 0.0
    d5, d6 = _edges_towards_origin(simplex, i, j, k, k)
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        t = d2 / (d2 - d6)
        return 1.0 - t, 0.0, t
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        t = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return 0.0, 1.0 - t, t
    total = va + vb + vc
    if not total > 0.0:  # a degenerate triangle: the caller stops
        return math.nan, math.nan, math.nan
    return va / total, vb / total, vc / total


@njit
def _face_sees_origin(simplex: FloatArray, i: int, j: int, k: int, opposite: int) -> int:
    """1 where the origin lies beyond face ``i, j, k`` (seen from ``opposite``), 0 where not, -1: flat."""
    a = simplex[i]
    ux, uy, uz = simplex[j, 0] - a[0], simplex[j, 1] - a[1], simplex[j, 2] - a[2]
    wx, wy, wz = simplex[k, 0] - a[0], simplex[k, 1] - a[1], simplex[k, 2] - a[2]
    nx, ny, nz = uy * wz - uz * wy, uz * wx - ux * wz, ux * wy - uy * wx
    origin = -(nx * a[0] + ny * a[1] + nz * a[2])
    d = simplex[opposite]
    vertex = nx * (d[0] - a[0]) + ny * (d[1] - a[1]) + nz * (d[2] - a[2])
    if vertex == 0.0:
        return -1
    return 1 if origin * vertex < 0.0 else 0


@njit
def reduce_simplex(simplex: FloatArray, size: int, weights: FloatArray) -> int:
    """Keep the vertices of ``simplex[:size]`` whose hull holds its point closest to the origin.

    Writes their weights into ``weights`` and moves them to the front; returns how many are
    kept, 0 where the origin lies inside a tetrahedron (distance 0), -1 where the simplex is
    degenerate.
    """
    weights[0], weights[1], weights[2], weights[3] = 1.0, 0.0, 0.0, 0.0
    if size == 2:
        a, b = simplex[0], simplex[1]
        ex, ey, ez = b[0] - a[0], b[1] - a[1], b[2] - a[2]
        length = ex * ex + ey * ey + ez * ez
        if not length > 0.0:
            return -1
        t = min(max(-(a[0] * ex + a[1] * ey + a[2] * ez) / length, 0.0), 1.0)
        weights[0], weights[1] = 1.0 - t, t
    elif size == 3:
        weights[0], weights[1], weights[2] = closest_on_triangle(simplex, 0, 1, 2)
    elif size == 4:
        best = math.inf
        seen = False
        for face in range(4):
            i, j, k, opposite = FACES[face, 0], FACES[face, 1], FACES[face, 2], FACES[face, 3]
            sees = _face_sees_origin(simplex, i, j, k, opposite)
            if sees < 0:
                return -1
            if sees == 0:
                continue
            seen = True
            wi, wj, wk = closest_on_triangle(simplex, i, j, k)
            px = wi * simplex[i, 0] + wj * simplex[j, 0] + wk * simplex[k, 0]
            py = wi * simplex[i, 1] + wj * simplex[j, 1] + wk * simplex[k, 1]
            pz = wi * simplex[i, 2] + wj * simplex[j, 2] + wk * simplex[k, 2]
            squared = px * px + py * py + pz * pz
            if squared < best:
                best = squared
                weights[0] = weights[1] = weights[2] = weights[3] = 0.0
                weights[i], weights[j], weights[k] = wi, wj, wk
        if not seen:
            return 0
    if not math.isfinite(weights[0]):
        return -1
    kept = 0
    for v in range(size):  # the vertices of positive weight, to the front, in order
        if weights[v] > 0.0:
            weights[kept] = weights[v]
            simplex[kept, 0], simplex[kept, 1], simplex[kept, 2] = simplex[v, 0], simplex[v, 1], simplex[v, 2]
            kept += 1
    return kept if kept else -1


@njit
def margin_state(
    g1: int,
    g2: int,
    cores: Cores,
    rotation: FloatArray,
    translation: FloatArray,
    below_m: float,
    above_m: float,
    guess: FloatArray,
    simplex: FloatArray,
    weights: FloatArray,
) -> int:
    """Whether shapes ``g1``'s and ``g2``'s cores are closer than ``below_m`` or farther than ``above_m`` [m].

    :data:`HIT` where a point of their Minkowski difference lies within ``below_m`` of the
    origin, :data:`CLEAR` where a support plane puts it beyond ``above_m``, else
    :data:`UNSURE`. The shapes as :func:`support` takes them. ``guess`` ``(3,)`` is the direction
    to start from (any: the pair's last, whose bound often decides at once; zero: the centres'
    difference), and receives the last one. ``simplex`` ``(4, 3)`` and ``weights`` ``(4,)`` are
    work arrays.
    """
    vx, vy, vz = guess[0], guess[1], guess[2]
    if vx == 0.0 and vy == 0.0 and vz == 0.0:
        vx = translation[g1, 0] - translation[g2, 0] + 1e-300  # never the zero vector
        vy = translation[g1, 1] - translation[g2, 1]
        vz = translation[g1, 2] - translation[g2, 2]
    size, lower = 0, 0.0
    for _ in range(MAX_ITERATIONS):
        ax, ay, az = support(g1, cores, rotation, translation, -vx, -vy, -vz)
        bx, by, bz = support(g2, cores, rotation, translation, vx, vy, vz)
        wx, wy, wz = ax - bx, ay - by, az - bz
        squared = vx * vx + vy * vy + vz * vz
        along = vx * wx + vy * wy + vz * wz
        if along > 0.0:  # every point p of the difference has p.v >= w.v, whatever v is
            lower = max(lower, along / math.sqrt(squared))
            if lower > above_m:
                return CLEAR
        if size and squared - along <= CONVERGED * squared:  # v lies in the difference
            return UNSURE
        simplex[size, 0], simplex[size, 1], simplex[size, 2] = wx, wy, wz
        size = reduce_simplex(simplex, size + 1, weights)
        if size <= 0:  # 0: the origin inside a tetrahedron (the cores overlap); -1: degenerate
            return HIT if size == 0 and below_m > 0.0 else UNSURE
        total = vx = vy = vz = 0.0
        for k in range(size):  # v: the simplex's closest point, a convex combination of its vertices
            total += weights[k]
            vx += weights[k] * simplex[k, 0]
            vy += weights[k] * simplex[k, 1]
            vz += weights[k] * simplex[k, 2]
        vx, vy, vz = vx / total, vy / total, vz / total
        guess[0], guess[1], guess[2] = vx, vy, vz
        squared = vx * vx + vy * vy + vz * vz
        if below_m > 0.0 and squared < below_m * below_m:
            return HIT
        if squared == 0.0:
            return UNSURE
    return UNSURE
