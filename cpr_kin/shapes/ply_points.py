"""The points of a PLY file: its ``vertex`` element's ``x y z``, its faces left unread.

A PLY file from a scanner or a modelling tool holds a cloud's points as its ``vertex``
element, often with more per-vertex properties (normals, colours, texture coordinates) and
a ``face`` element of polygons of mixed sizes (Blender writes quads and n-gons: roboplan's
example cloud). A reader of the whole mesh has to walk every polygon and one that expects
a fixed polygon size refuses such a file (trimesh: "PLY is unexpected length!"); a point
cloud needs only the vertices, which PLY writers put first. So the header is parsed
(``format`` ``ascii``, ``binary_little_endian`` or ``binary_big_endian``; ``element`` and
``property`` lines, scalar or ``list``), the elements before ``vertex`` skipped (those of
fixed size only), and the vertex rows read as one numpy record array.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.errors import ObstacleError

FloatArray = NDArray[np.float64]

SCALAR_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
}  # fmt: skip
"""PLY's scalar types and numpy's codes for them (without byte order)."""
BYTE_ORDERS = {"binary_little_endian": "<", "binary_big_endian": ">", "ascii": ""}
"""PLY's formats and numpy's byte order of each (none for ``ascii``)."""
MAX_HEADER_BYTES = 65_536
"""Longest header read [bytes]; a file without ``end_header`` within it is refused."""


@dataclass(frozen=True)
class PlyElement:
    """One ``element`` of a PLY header.

    Attributes:
        name: its name (``vertex``, ``face``, ...).
        count: how many rows it has.
        properties: ``(name, type)`` of each scalar property, ``type`` a key of
            :data:`SCALAR_TYPES`, in order; ``type`` is ``list`` for a list property.
    """

    name: str
    count: int
    properties: tuple[tuple[str, str], ...]

    @property
    def has_lists(self) -> bool:
        """Whether a property is a ``list`` (rows of varying size)."""
        return any(kind == "list" for _, kind in self.properties)

    def dtype(self, order: str) -> np.dtype:
        """Numpy's record type of one row (no lists), in byte ``order``."""
        return np.dtype(
            [(f"p{k}", order + SCALAR_TYPES[kind]) for k, (_, kind) in enumerate(self.properties)]
        )


def read_ply_points(data: bytes, max_points: int, path: Path) -> FloatArray:
    """The ``(N, 3)`` ``x y z`` of the ``vertex`` rows of the PLY file ``path``'s bytes ``data``.

    Raises:
        ObstacleError: no PLY header, an unknown format or type, no vertex element with
            ``x``, ``y``, ``z``, more than ``max_points`` vertices, a vertex element after one
            with lists (in a binary file) or with lists itself, fewer bytes than its rows need.
    """
    what = f"point cloud '{path}'"
    fmt, elements, body = _header(data, what)
    vertex = next((e for e in elements if e.name == "vertex"), None)
    names = [] if vertex is None else [name for name, _ in vertex.properties]
    if vertex is None or not {"x", "y", "z"} <= set(names):
        found = [e.name for e in elements]
        raise ObstacleError(f"{what}: no PLY vertex element with x, y, z properties; its elements: {found}")
    if vertex.count > max_points:
        raise ObstacleError(f"{what} holds {vertex.count} vertices; at most {max_points} are allowed")
    columns = [names.index(axis) for axis in "xyz"]
    before = elements[: elements.index(vertex)]
    if fmt == "ascii":
        if vertex.has_lists:
            raise ObstacleError(
                f"{what}: its vertex element has list properties; a cloud's vertices have none"
            )
        skipped = sum(e.count for e in before)
        lines = data[body:].decode("ascii").splitlines()[skipped : skipped + vertex.count]
        if len(lines) < vertex.count:
            raise ObstacleError(f"{what}: {len(lines)} vertex lines of the {vertex.count} its header gives")
        if not lines:  # no rows: numpy's reader would warn of an empty input
            return np.empty((0, 3))
        return np.loadtxt(lines, usecols=columns, ndmin=2, dtype=float)
    order = BYTE_ORDERS[fmt]
    if vertex.has_lists or any(e.has_lists for e in before):
        raise ObstacleError(
            f"{what}: its vertices come after an element with lists, or hold lists; write the vertex "
            "element first, of scalar properties (as PLY writers do)"
        )
    start = body + sum(e.count * e.dtype(order).itemsize for e in before)
    row = vertex.dtype(order)
    if len(data) - start < vertex.count * row.itemsize:
        raise ObstacleError(
            f"{what}: {max(len(data) - start, 0)} bytes of vertices, {vertex.count * row.itemsize} needed "
            f"for the {vertex.count} its header gives; the file is cut short"
        )
    records = np.frombuffer(data, dtype=row, count=vertex.count, offset=start)
    return np.column_stack([records[f"p{c}"] for c in columns]).astype(float)


def _header(data: bytes, what: str) -> tuple[str, list[PlyElement], int]:
    """The format, the elements and the offset of the first byte after ``end_header``."""
    end = data.find(b"end_header", 0, MAX_HEADER_BYTES)
    newline = data.find(b"\n", end)
    if not data.startswith(b"ply") or end < 0 or newline < 0:
        raise ObstacleError(f"{what}: no PLY header ('ply' ... 'end_header' within {MAX_HEADER_BYTES} bytes)")
    fmt = ""
    elements: list[tuple[str, int, list[tuple[str, str]]]] = []
    for line in data[:end].decode("ascii", errors="replace").splitlines()[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format" and len(words) >= 2:
            fmt = words[1]
        elif words[0] == "element" and len(words) == 3 and words[2].isdigit():
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property" and elements and len(words) == 3 and words[1] in SCALAR_TYPES:
            elements[-1][2].append((words[2], words[1]))
        elif words[0] == "property" and elements and len(words) == 5 and words[1] == "list":
            elements[-1][2].append((words[4], "list"))
        else:
            raise ObstacleError(f"{what}: PLY header line '{line[:60]}' is not understood")
    if fmt not in BYTE_ORDERS:
        raise ObstacleError(f"{what}: PLY format '{fmt}'; one of {list(BYTE_ORDERS)} is read")
    return fmt, [PlyElement(name, count, tuple(props)) for name, count, props in elements], newline + 1
