"""OctoMap's octrees, from a file (``.bt``, ``.ot``) or a message's data, as occupied voxels.

An OctoMap ``OcTree`` is 16 levels deep: its voxels of side ``resolution`` [m] sit on the grid
anchored at the tree frame's origin (key ``k`` spans ``[k - 32768, k - 32767) * resolution``),
the grid :mod:`cpr_kin.shapes.point_clouds` uses, and a node whose eight children agree is pruned to
one. Two encodings, each a header of text lines (``id OcTree``, ``size``, ``res``, ``data``)
followed by the tree depth first:

- binary (``.bt``, ``octomap_msgs/Octomap`` with ``binary: true``): each inner node is two
  bytes, two bits a child (``01`` free, ``10`` occupied, ``11`` inner, ``00`` unknown);
- full (``.ot``, ``binary: false``): each node is its log-odds (float32) and a byte whose bits
  say which children exist; a leaf is occupied when its log-odds is at least 0 (probability
  0.5, OctoMap's default threshold).

A pruned occupied node becomes the voxels it covers, so a scene reads the same obstacle as
from the points. Only ``OcTree`` is read (a ``ColorOcTree`` and others carry other data).
"""

from __future__ import annotations

import struct
from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.errors import ObstacleError
from cpr_kin.common.names import shown
from cpr_kin.common.user_files import UserFileError, read_bytes

FloatArray = NDArray[np.float64]

SUFFIXES = (".bt", ".ot")
"""The octree files :func:`read_octree` reads."""
MAX_OCTREE_BYTES = 100_000_000
"""Largest octree file [bytes]."""
MAX_VOXELS = 2_000_000
"""Most occupied voxels one octree may hold, pruned nodes counted as the voxels they cover."""
TREE_DEPTH = 16
"""OctoMap's tree depth: keys 0 to 2**16 - 1 on each axis."""
_CENTRE_KEY = 2 ** (TREE_DEPTH - 1)
_HEADERS = {b"# Octomap OcTree binary file": True, b"# Octomap OcTree file": False}


@dataclass(frozen=True)
class OccupiedVoxels:
    """The occupied voxels of an octree.

    Attributes:
        centres: ``(N, 3)`` their centres in the tree's frame [m].
        resolution_m: their side [m].
        node_count: the tree's nodes, free, occupied and inner (the ``size`` of its header).
    """

    centres: FloatArray
    resolution_m: float
    node_count: int = 0


def read_octree(path: Path) -> OccupiedVoxels:
    """The occupied voxels of an OctoMap file, binary (``.bt``) or full (``.ot``).

    Raises:
        ObstacleError: a missing, too large or broken file, a tree other than ``OcTree``, too
            many voxels.
    """
    path = Path(path)
    what = f"octree '{path}'"
    try:
        data = read_bytes(path, MAX_OCTREE_BYTES, "octree")
    except UserFileError as exc:
        raise ObstacleError(str(exc)) from None
    first = data.partition(b"\n")[0]
    binary = _HEADERS.get(first.strip())
    if binary is None:
        raise ObstacleError(
            f"{what} starts with {shown(first[:60].decode('latin-1'))}; an OctoMap file starts "
            f"with one of {[h.decode() for h in _HEADERS]}"
        )
    fields: dict[str, str] = {}
    offset = len(first) + 1
    while offset < len(data):
        end = data.find(b"\n", offset)
        words = data[offset : len(data) if end < 0 else end].decode("latin-1").split()
        offset = len(data) if end < 0 else end + 1
        if words and words[0] == "data":
            break
        if words and not words[0].startswith("#"):
            fields[words[0]] = " ".join(words[1:])
    else:
        raise ObstacleError(f"{what} has no 'data' line: the header ends without the tree")
    try:
        resolution_m, size = float(fields["res"]), int(fields["size"])
    except (KeyError, ValueError):
        raise ObstacleError(f"{what}: header {fields} needs 'res' (a number) and 'size' (a count)") from None
    return octree_voxels(
        data[offset:] if size else b"", resolution_m, binary, what, tree_id=fields.get("id", "OcTree")
    )


def octree_voxels(
    data: bytes, resolution_m: float, binary: bool, what: str, tree_id: str = "OcTree"
) -> OccupiedVoxels:
    """The occupied voxels of an octree's data, the bytes after its header (module docstring).

    Args:
        data: the tree, depth first; empty for an empty tree.
        resolution_m: the side of its smallest voxels [m].
        binary: the binary encoding (``.bt``), else the full one (``.ot``).
        what: the tree, for messages (e.g. ``"octree 'room.bt'"``).
        tree_id: the tree's type, ``OcTree`` the one read.

    Raises:
        ObstacleError: a type other than ``OcTree``, a resolution that is not a positive number,
            data that ends early or goes on after the tree, too many voxels.
    """
    if tree_id != "OcTree":
        raise ObstacleError(f"{what} is a {shown(tree_id)}; only OctoMap's 'OcTree' is read")
    if not (np.isfinite(resolution_m) and resolution_m > 0):
        raise ObstacleError(f"{what}: resolution = {shown(resolution_m)} must be a number > 0 m")
    leaves: list[tuple[int, int, int, int]] = []  # occupied: key of the lowest corner, depth
    walk = _BinaryWalk(data, what) if binary else _FullWalk(data, what)
    if data:
        walk.node(0, 0, 0, 0, leaves)
        if walk.offset != len(data):
            raise ObstacleError(
                f"{what}: {len(data) - walk.offset} bytes follow the tree's end; the data is not one tree"
            )
    spans = [1 << (TREE_DEPTH - depth) for *_, depth in leaves]
    count = sum(span**3 for span in spans)
    if count > MAX_VOXELS:
        raise ObstacleError(f"{what} holds {count} occupied voxels; at most {MAX_VOXELS} are read")
    keys = [
        np.stack(np.meshgrid(*(np.arange(k, k + span) for k in key), indexing="ij"), axis=-1).reshape(-1, 3)
        for (*key, _), span in zip(leaves, spans, strict=True)
    ]
    grid = np.vstack(keys) if keys else np.empty((0, 3), dtype=np.int64)
    return OccupiedVoxels((grid - _CENTRE_KEY + 0.5) * resolution_m, float(resolution_m), walk.nodes)


class _Walk(ABC):
    """Reads a tree depth first from ``data``, appending its occupied leaves."""

    def __init__(self, data: bytes, what: str) -> None:
        self.data, self.what, self.offset = data, what, 0
        self.nodes = 0

    def take(self, size: int) -> bytes:
        """The next ``size`` bytes; raises :class:`ObstacleError` where the data ends."""
        if self.offset + size > len(self.data):
            raise ObstacleError(f"{self.what}: the data ends inside the tree, at byte {len(self.data)}")
        chunk = self.data[self.offset : self.offset + size]
        self.offset += size
        return chunk

    @abstractmethod
    def node(self, x: int, y: int, z: int, depth: int, leaves: list[tuple[int, int, int, int]]) -> None:
        """Read the node at key corner ``(x, y, z)`` and ``depth`` (0: the root), and below it."""

    @staticmethod
    def corner(x: int, y: int, z: int, depth: int, child: int) -> tuple[int, int, int]:
        """The key corner of ``child`` (bit 0: +x, 1: +y, 2: +z) of the node at ``depth``."""
        half = 1 << (TREE_DEPTH - depth - 1)
        return x + (child & 1) * half, y + (child >> 1 & 1) * half, z + (child >> 2 & 1) * half

    def deeper(self, depth: int) -> int:
        """``depth + 1``, if a node may sit there; raises :class:`ObstacleError` below the last level."""
        if depth + 1 > TREE_DEPTH:
            raise ObstacleError(
                f"{self.what}: a node below the tree's {TREE_DEPTH} levels; the data is broken"
            )
        return depth + 1


class _BinaryWalk(_Walk):
    def node(self, x: int, y: int, z: int, depth: int, leaves: list[tuple[int, int, int, int]]) -> None:
        low, high = self.take(2)
        self.nodes += depth == 0  # the root; the others are counted as their parent's children
        below = self.deeper(depth)
        inner = []
        for child in range(8):
            bits = ((low if child < 4 else high) >> 2 * (child % 4)) & 3
            self.nodes += bits != 0
            if bits == 2:  # an occupied leaf
                leaves.append((*self.corner(x, y, z, depth, child), below))
            elif bits == 3:
                inner.append(self.corner(x, y, z, depth, child))
        for corner in inner:
            if below == TREE_DEPTH:
                raise ObstacleError(f"{self.what}: a voxel with children; the data is broken")
            self.node(*corner, below, leaves)


class _FullWalk(_Walk):
    def node(self, x: int, y: int, z: int, depth: int, leaves: list[tuple[int, int, int, int]]) -> None:
        (log_odds,) = struct.unpack("<f", self.take(4))
        (children,) = self.take(1)
        self.nodes += 1
        if not children:
            if log_odds >= 0.0:  # at least OctoMap's default threshold, probability 0.5
                leaves.append((x, y, z, depth))
            return
        below = self.deeper(depth)
        for child in range(8):
            if children >> child & 1:
                self.node(*self.corner(x, y, z, depth, child), below, leaves)
