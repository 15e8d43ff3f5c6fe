"""What a robot's near cells are known to clear, kept on disk between processes.

A near pair's cell (:mod:`cpr_kin.collision.near_cells`) is tested by coal once per margin, at its
centre, and the answer holds for every configuration of the cell: it is the robot's (its two
links and the joints between them), whatever the scene. Where a link is concave, the test goes
to its exact mesh, a descent into triangles (tens of microseconds a cell): a UR5 among shelves
tests thousands of cells in its first plans. A process that starts again would learn them
again; the memory is kept in the disk cache (:mod:`cpr_kin.common.disk_cache`) instead, and the
robot's next process starts with what the earlier ones learned.

It is named by a digest of everything a test's answer depends on (:func:`cells_digest`): the
kinematic model, the pairs' shapes, placements and exact meshes, the grids and slacks, the
code that tests (this package's deciding modules) and coal's and Pinocchio's versions. A file
of another shape, or one that cannot be read, is an empty memory.

A memory only ever skips coal where a test at a cell's centre cleared a larger margin, or where
the distance measured there, less how far a configuration lies from the centre, does; a margin
test is coal's whether its cells know it or not: what is kept changes how fast a plan is, never
what it finds. A file holding a NaN is not read (a NaN would clear every margin).
"""

from __future__ import annotations

import atexit
import hashlib
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import coal
import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.common.disk_cache import read_array, write_array
from cpr_kin.shapes.coal_queries import swept_radius_m

if TYPE_CHECKING:
    from cpr_kin.bounds.pair_cells import CellGrids
    from cpr_kin.shapes.exact_meshes import ExactMesh

Float32Array = NDArray[np.float32]

FORMAT = b"near-cells-2"
"""Named in the digest: a change to what a file holds makes the memories anew."""
DECIDING_MODULES = (
    "collision/near_cells.py",
    "collision/coal_pools.py",
    "collision/decisive.py",
    "bounds/pair_cells.py",
    "shapes/exact_pairs.py",
    "shapes/mesh_pieces.py",
    "shapes/held_whole.py",
    "shapes/vertex_witness.py",
    "shapes/coal_queries.py",
)
"""The files, under the package, whose code decides a cell's test: part of the digest."""
KEPT_BYTES = 64 << 20
"""The memories kept on disk add up to this at most [bytes] (a robot's is a few MB at most: the
UR5's 0.6 MB); beyond it, those least recently read or kept are removed (another version of the
code or of a robot's files names new ones, and the old ones are never read again)."""
SAVE_AFTER_S = 0.05
"""Time [s] spent learning since the memory was last kept that has it kept again at once
(the rest is kept when the process ends)."""


@dataclass
class LearnedCells:
    """What the cells are known to clear, on one kind of geometry (hulls, or the exact meshes).

    Attributes:
        size: the cells.
        cleared: ``(C,)`` per cell, the largest margin [m] it is known to clear.
        refused: ``(C,)`` per cell, the smallest margin [m] it is known not to clear.
        centre_m: ``(C,)`` per cell, a lower bound of the pair's distance at its centre [m]
            (``-inf``: not measured; measured where the cell does not clear a margin asked).
    """

    size: int
    cleared: Float32Array = field(init=False)
    refused: Float32Array = field(init=False)
    centre_m: Float32Array = field(init=False)

    def __post_init__(self) -> None:
        self.cleared = np.full(self.size, -np.inf, dtype=np.float32)
        self.refused = np.full(self.size, np.inf, dtype=np.float32)
        self.centre_m = np.full(self.size, -np.inf, dtype=np.float32)

    def arrays(self) -> tuple[Float32Array, Float32Array, Float32Array]:
        """``cleared``, ``refused`` and ``centre_m``: what is kept."""
        return self.cleared, self.refused, self.centre_m

    def merge(self, cleared: Float32Array, refused: Float32Array, centre_m: Float32Array) -> None:
        """Take in what another memory of the same cells knows: the larger bounds, the smaller refused."""
        np.maximum(self.cleared, cleared, out=self.cleared)
        np.minimum(self.refused, refused, out=self.refused)
        np.maximum(self.centre_m, centre_m, out=self.centre_m)


class CellMemory:
    """The near cells' memories on the hulls and on the meshes, kept under ``digest`` on disk.

    Args:
        size: the cells of every grid.
        on_meshes_apart: whether the meshes' memory is its own (some pair has an exact mesh);
            otherwise both kinds share one.
        digest: the name of the memory on disk (:func:`cells_digest`); ``None``: kept in memory only.

    The memory is read on construction, kept again once :data:`SAVE_AFTER_S` of learning has
    accumulated (:meth:`learned`), and at the process's end (:func:`keep_learned`).
    """

    def __init__(self, size: int, on_meshes_apart: bool, digest: str | None) -> None:
        hulls = LearnedCells(size)
        self.kinds = {False: hulls, True: LearnedCells(size) if on_meshes_apart else hulls}
        self.digest = digest
        self._unsaved_s = 0.0
        self._changed = False
        if digest is not None:
            self._read(digest)
            _LIVE.add(self)

    def learned(self, seconds: float) -> None:
        """Note that the cells learned for ``seconds`` [s]; kept once that adds up to :data:`SAVE_AFTER_S`."""
        self._changed = True
        self._unsaved_s += seconds
        if self._unsaved_s >= SAVE_AFTER_S:
            self.save()

    def save(self) -> None:
        """Keep what is known on disk, merged with what other processes kept there meanwhile."""
        if self.digest is None or not self._changed:
            return
        self._read(self.digest)
        stacked = np.stack([array for kind in self._distinct() for array in kind.arrays()])
        write_array("near-cells", self.digest, stacked, KEPT_BYTES)
        self._unsaved_s, self._changed = 0.0, False

    def _distinct(self) -> list[LearnedCells]:
        hulls, meshes = self.kinds[False], self.kinds[True]
        return [hulls] if meshes is hulls else [hulls, meshes]

    def _read(self, digest: str) -> None:
        """Merge in the memory kept on disk under ``digest``, if there is one of these cells."""
        kinds = self._distinct()
        found = read_array("near-cells", digest)
        kept = len(kinds[0].arrays())
        shape = (kept * len(kinds), kinds[0].size)
        if found is None or found.dtype != np.float32 or found.shape != shape or np.isnan(found).any():
            return
        for k, kind in enumerate(kinds):
            kind.merge(*found[kept * k : kept * (k + 1)])


_LIVE: weakref.WeakSet[CellMemory] = weakref.WeakSet()
"""The memories kept on disk that are still in use."""


def keep_learned() -> None:
    """Keep on disk what every memory still in use learned since it was last kept.

    Run when the process ends (registered with :mod:`atexit`; a process that ends without
    Python's exit functions calls it itself, as ``cpr-plan`` does).
    """
    for memory in list(_LIVE):
        memory.save()


atexit.register(keep_learned)


def cells_digest(
    model: Any,
    geometry_model: Any,
    pairs: Sequence[tuple[int, int]],
    grids: CellGrids,
    exact_meshes: Mapping[int, ExactMesh],
) -> str:
    """The SHA-256 naming the near cells of ``pairs`` (geometry indices of ``geometry_model``).

    Of: :data:`FORMAT`, coal's and Pinocchio's versions, the deciding modules' code, the model
    (its joints, placements and limits, serialised), each pair's two geometries (shape, parent
    joint, placement) and exact meshes (triangles and placement) and the grids' arrays. The
    constants a test adds to a margin are in the deciding modules' code.
    """
    digest = hashlib.sha256(FORMAT)
    digest.update(f"coal {coal.__version__} pinocchio {pin.__version__}".encode())
    package = Path(__file__).resolve().parents[1]
    for name in DECIDING_MODULES:
        digest.update(name.encode() + (package / name).read_bytes())
    digest.update(model.saveToString().encode())
    geometries = sorted({g for pair in pairs for g in pair})
    for g in geometries:
        placed = geometry_model.geometryObjects[g]
        digest.update(b"geometry %d joint %d " % (g, placed.parentJoint))
        digest.update(placed.placement.homogeneous.tobytes())
        digest.update(_shape_bytes(placed.geometry))
    digest.update(np.asarray(pairs, dtype=np.int64).tobytes())
    for g in geometries:
        mesh = exact_meshes.get(g)
        if mesh is not None:
            digest.update(b"mesh %d" % g + mesh.triangles.tobytes())
            digest.update(mesh.mesh_in_shape.homogeneous.tobytes())
    for array in (grids.slack_m, *grids.arrays()):
        digest.update(np.ascontiguousarray(array).tobytes())
    return digest.hexdigest()


def _shape_bytes(shape: Any) -> bytes:
    """What a coal shape is: a convex's points (a robot's hulls, read at once), any other's serialisation."""
    kind = type(shape).__name__.encode() + np.float64(swept_radius_m(shape)).tobytes()
    if isinstance(shape, coal.ConvexBase):
        return kind + np.ascontiguousarray(shape.points(), dtype=float).tobytes() + b"%d" % shape.num_polygons
    return kind + str(shape.saveToString()).encode()
