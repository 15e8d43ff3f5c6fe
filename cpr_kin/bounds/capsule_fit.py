"""A small capsule about a set of points: the bound the cheap distance tests place on a mesh.

The pair bounds (:mod:`cpr_kin.bounds.pair_bounds`, :mod:`cpr_kin.bounds.self_bounds`) enclose each robot
geometry in a capsule; the tighter it is, the fewer configurations they leave to coal. A
mesh's bounding box gives one (its longest side as the axis, the box's half diagonal across
it as the radius), 1.4 times a round link's radius. Here the capsule is fitted to the
mesh's vertices instead, along each of a few candidate axes (the vertices' principal axes
and the frame's own): the radius is that of the smallest circle holding the vertices
projected across the axis (Welzl's algorithm, on their 2-D hull), and the segment is the
shortest along the axis that keeps every vertex within that radius of it. A capsule is
convex, so one holding every vertex holds the convex hull of the vertices, hence the mesh.
The candidate of least volume is kept.

The fit is memoised by the vertices' bytes: a robot's meshes are fitted once per process,
however many collision worlds are built for it; a mesh's (more than :data:`HULL_ABOVE` points)
is also kept on disk (:mod:`cpr_kin.common.disk_cache`), so that a new process, each
``cpr-plan`` call, reads it instead of fitting it again (tens of milliseconds a mesh).
"""

from __future__ import annotations

import functools
import hashlib
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.disk_cache import cached_array

FloatArray = NDArray[np.float64]

FIT_VERSION = b"capsule-fit-1"
"""Named in the disk cache's digest: a change to the fit changes it, and fits are made anew."""
HULL_ABOVE = 64
"""Point sets larger than this are reduced to their convex hull's vertices before a fit."""
CONTAINMENT_TOLERANCE_M = 1e-9
"""Added to a fitted radius [m]: rounding in the fit never leaves a vertex outside."""


class Capsule(NamedTuple):
    """A segment grown by a radius.

    Attributes:
        ends: ``(2, 3)`` the segment's end points [m] (equal for a sphere).
        radius: [m].
    """

    ends: FloatArray
    radius: float

    @property
    def volume(self) -> float:
        """[m^3]."""
        length = float(np.linalg.norm(self.ends[1] - self.ends[0]))
        return float(np.pi * self.radius**2 * (length + 4.0 * self.radius / 3.0))

    def distances(self, points: FloatArray) -> FloatArray:
        """``(N,)`` distance [m] of each of ``points`` ``(N, 3)`` to the segment (not the surface)."""
        start, direction = self.ends[0], self.ends[1] - self.ends[0]
        length_sq = float(direction @ direction)
        share = np.zeros(len(points)) if length_sq == 0.0 else (points - start) @ direction / length_sq
        closest = start + np.clip(share, 0.0, 1.0)[:, None] * direction
        return np.asarray(np.linalg.norm(points - closest, axis=1))


def enclosing_circle(points: FloatArray) -> tuple[FloatArray, float]:
    """The smallest circle holding ``points`` ``(N, 2)``: centre ``(2,)`` and radius [m].

    Welzl's randomised incremental algorithm (in the iterative form of de Berg et al.,
    *Computational Geometry*, 4.7), on the points' convex hull; expected linear time. The
    radius returned is the largest distance from the centre, so it holds every point even
    where rounding moved the centre.
    """
    candidates = _hull_points(points)
    order = np.random.default_rng(0).permutation(len(candidates))  # a fixed order: the same fit each run
    shuffled = [candidates[k] for k in order]
    centre, radius = shuffled[0], 0.0
    for i in range(1, len(shuffled)):
        if _outside(shuffled[i], centre, radius):
            centre, radius = shuffled[i], 0.0
            for j in range(i):
                if _outside(shuffled[j], centre, radius):
                    centre, radius = _circle_of_two(shuffled[i], shuffled[j])
                    for k in range(j):
                        if _outside(shuffled[k], centre, radius):
                            centre, radius = _circle_of_three(shuffled[i], shuffled[j], shuffled[k])
    centre = np.asarray(centre, dtype=float)
    return centre, float(np.max(np.linalg.norm(points - centre, axis=1)))


def capsule_along(points: FloatArray, axis: FloatArray) -> Capsule:
    """The capsule along ``axis`` ``(3,)`` of least radius, then shortest, holding ``points`` ``(N, 3)``."""
    frame = frame_about(axis)
    axis, basis = frame[:, 2], frame[:, :2].T  # basis (2, 3): orthonormal, across the axis
    along, plane = points @ axis, points @ basis.T
    centre, radius = enclosing_circle(plane)
    off_axis = np.linalg.norm(plane - centre, axis=1)
    reach = np.sqrt(np.maximum(radius**2 - off_axis**2, 0.0))  # how far along the axis each may lie
    low, high = float(np.min(along + reach)), float(np.max(along - reach))
    if low > high:  # a sphere holds them: about the middle, as large as its farthest point
        low = high = (low + high) / 2
        radius = float(np.max(np.hypot(along - low, off_axis)))
    base = centre @ basis
    ends = np.array([base + low * axis, base + high * axis])
    return Capsule(ends, radius + CONTAINMENT_TOLERANCE_M)


def frame_about(axis: FloatArray) -> FloatArray:
    """``(3, 3)`` a right-handed orthonormal frame whose z column is ``axis`` ``(3,)`` (normalised)."""
    z = axis / np.linalg.norm(axis)
    x = np.cross(np.eye(3)[int(np.argmin(np.abs(z)))], z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def fitted_capsule(points: FloatArray) -> Capsule:
    """The capsule of least volume holding ``points`` ``(N, 3)`` along their principal or frame axes."""
    points = np.ascontiguousarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3 or not len(points) or not np.all(np.isfinite(points)):
        raise ValueError(f"points of shape {points.shape} must be (N >= 1, 3), finite")
    return _fitted(points.tobytes(), len(points))


@functools.lru_cache(maxsize=512)
def _fitted(data: bytes, count: int) -> Capsule:
    points = np.frombuffer(data, dtype=float).reshape(count, 3)
    if count <= HULL_ABOVE:  # a primitive's corners: fitted in less time than a file is read
        return _fit(points)

    def compute() -> FloatArray:
        capsule = _fit(points)
        return np.append(capsule.ends.ravel(), capsule.radius)

    digest = hashlib.sha256(FIT_VERSION + data).hexdigest()
    kept = cached_array("capsule-fits", f"{digest}-{count}", compute)
    if not _holds(kept, points):  # a file edited: fitted anew
        kept = compute()
    return Capsule(kept[:6].reshape(2, 3).copy(), float(kept[6]))


def _holds(kept: FloatArray, points: FloatArray) -> bool:
    """Whether ``kept`` (ends and radius, ``(7,)``) is a capsule holding every one of ``points``.

    A bound read from disk is checked before the distance tests trust it (a fraction of a
    millisecond a mesh, against the fit's tens).
    """
    if kept.shape != (7,) or not np.all(np.isfinite(kept)) or kept[6] < 0.0:
        return False
    capsule = Capsule(kept[:6].reshape(2, 3), float(kept[6]))
    return bool(np.all(capsule.distances(points) <= capsule.radius))


def _fit(points: FloatArray) -> Capsule:
    """:func:`fitted_capsule`'s fit, not memoised."""
    points = _hull_points(points)
    centred = points - points.mean(axis=0)
    principal = np.linalg.svd(centred, full_matrices=False)[2] if len(points) > 1 else np.eye(3)
    axes = [*principal, *np.eye(3)]
    return min((capsule_along(points, axis) for axis in axes), key=lambda capsule: capsule.volume)


def _hull_points(points: FloatArray) -> FloatArray:
    """The vertices of ``points``' convex hull (all of them where it is flat or few).

    Up to :data:`HULL_ABOVE` points are all kept: the fits take any superset of the hull's
    vertices, and a primitive's few corners (a box's eight) then need no SciPy in a process.
    """
    if len(points) <= max(HULL_ABOVE, points.shape[1] + 1):
        return points
    from scipy.spatial import ConvexHull, QhullError  # only a mesh's geometry needs it: not at import

    try:
        hull: FloatArray = points[ConvexHull(points).vertices]
        return hull
    except QhullError:  # coplanar or collinear: every point is a candidate
        return points


def _outside(point: FloatArray, centre: FloatArray, radius: float) -> bool:
    return bool(np.hypot(point[0] - centre[0], point[1] - centre[1]) > radius * (1 + 1e-12) + 1e-15)


def _circle_of_two(a: FloatArray, b: FloatArray) -> tuple[FloatArray, float]:
    centre = (a + b) / 2
    return centre, float(np.hypot(*(a - centre)))


def _circle_of_three(a: FloatArray, b: FloatArray, c: FloatArray) -> tuple[FloatArray, float]:
    """The circle through ``a``, ``b``, ``c``; the widest pair's where they are (nearly) collinear."""
    bx, by = b - a
    cx, cy = c - a
    determinant = 2.0 * (bx * cy - by * cx)
    if abs(determinant) <= 1e-18:
        return max((_circle_of_two(p, q) for p, q in ((a, b), (a, c), (b, c))), key=lambda pair: pair[1])
    b_sq, c_sq = bx * bx + by * by, cx * cx + cy * cy
    offset = np.array([cy * b_sq - by * c_sq, bx * c_sq - cx * b_sq]) / determinant
    return a + offset, float(np.hypot(*offset))
