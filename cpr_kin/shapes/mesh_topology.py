"""What an exact link mesh is made of beyond coal's triangle model: triangles, pieces, hull planes.

:func:`~cpr_kin.shapes.exact_meshes.exact_meshes` needs of each concave link mesh its triangles'
corners, a vertex of each connected piece of it and its convex hull's facet planes. Each is
computed once per mesh (its file's bytes, scale and vertices) and kept on disk
(:mod:`cpr_kin.common.disk_cache`): a new process that loads the robot reads them, and needs
neither SciPy's graph routines (a tenth of a second to import) nor Qhull for them. A kept array
that does not fit the mesh (cut short, edited: the wrong shape, an index out of range, a value
not finite) is computed again.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.arrays import distinct_sorted
from cpr_kin.common.disk_cache import cached_array
from cpr_kin.shapes.mesh_geometry import hull_planes

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

MAX_PIECES = 64
"""A mesh of more connected pieces than this is not tested for holding another shape (module
:mod:`cpr_kin.shapes.exact_pairs`): where its hull is penetrated, the hull decides."""


@dataclass(frozen=True)
class MeshTopology:
    """A mesh's triangles, pieces and hull, in the mesh's frame [m].

    Attributes:
        triangles: ``(F, 3, 3)`` the triangles' corners.
        piece_points: ``(K, 3)`` a vertex of each connected piece, ``None`` for more than
            :data:`MAX_PIECES` pieces.
        corners: ``(V, 3)`` the triangles' corners, each once.
        hull_planes: ``(H, 4)`` the facets of the corners' convex hull, ``n . x + d <= 0``
            inside (:func:`~cpr_kin.shapes.mesh_geometry.hull_planes`; none for a flat mesh).
    """

    triangles: FloatArray
    piece_points: FloatArray | None
    corners: FloatArray
    hull_planes: FloatArray


def mesh_topology(bvh: Any, content: bytes) -> MeshTopology:
    """The topology of coal's triangle model ``bvh``, kept on disk by ``content``: what the mesh is from.

    ``content``: the mesh file's bytes and scale (the vertices are added here), so that
    another file, scale or loader's vertices make their own entries.
    """
    vertices = np.asarray(bvh.vertices(), dtype=float).reshape(-1, 3)
    count = bvh.num_tris
    digest = hashlib.sha256(content + vertices.tobytes()).hexdigest()

    def indices() -> IntArray:
        rows = (bvh.tri_indices(i) for i in range(count))  # coal hands them out one by one
        return np.array([[t[0], t[1], t[2]] for t in rows], dtype=np.int64).reshape(-1, 3)

    def faces_fit(found: NDArray[Any]) -> bool:
        return _indices_of(found, len(vertices)) and found.shape == (count, 3)

    faces = cached_array("mesh-faces", f"{digest}-{count}", indices, faces_fit)
    used = distinct_sorted(faces)  # np.unique would import numpy.ma into a new process
    corners = vertices[used]
    pieces = cached_array(
        "mesh-components",
        digest,
        lambda: used[_first_of_each_piece(faces, len(vertices), used)],
        lambda found: _indices_of(found, len(vertices)) and found.ndim == 1 and 0 < len(found) <= len(used),
    )
    planes = cached_array(
        "hull-planes",
        digest,
        lambda: hull_planes(corners),
        lambda found: (
            found.dtype == np.float64
            and found.ndim == 2
            and found.shape[1] == 4
            and bool(np.isfinite(found).all())
        ),
    )
    points = vertices[pieces] if len(pieces) <= MAX_PIECES else None
    return MeshTopology(vertices[faces], points, corners, planes)


def _first_of_each_piece(faces: IntArray, vertex_count: int, used: IntArray) -> IntArray:
    """Where in ``used`` (the vertices the ``faces`` use, ascending) each connected piece first appears."""
    from scipy.sparse import coo_matrix  # only a first load of a mesh needs them
    from scipy.sparse.csgraph import connected_components

    edges = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])), shape=(vertex_count,) * 2)
    _, label = connected_components(graph, directed=False)
    first: IntArray = np.unique(label[used], return_index=True)[1]
    return first


def _indices_of(found: NDArray[Any], vertex_count: int) -> bool:
    """Whether ``found`` holds vertex indices of a mesh of ``vertex_count`` vertices."""
    return bool(
        found.dtype == np.int64 and (found.size == 0 or (found.min() >= 0 and found.max() < vertex_count))
    )
