"""Point clouds as obstacles: read from a file, turned into occupied voxels, split into blocks.

A depth camera gives points, not shapes. A cloud becomes the cubes of side ``resolution``
[m] that hold at least one of its points (a voxel grid anchored at the cloud frame's origin):
their union contains every point, so a clearance to the voxels is at most the clearance to
the points (safe), and coal measures it on an OcTree (``coal.makeOctree``). The voxels are
split into blocks of :data:`BLOCK_M` per side, each its own obstacle: the planner's cheap
bounds then see each block's own box, not the whole cloud's, and spare coal the blocks far
from the robot.

Files (:func:`read_points`): ``.npy`` (an ``(N, 3)`` array), ``.xyz`` / ``.txt`` (three numbers
a line, more columns ignored), ``.ply`` (its vertices, :mod:`cpr_kin.shapes.ply_points`) and
``.pcd`` (PCL's format, ASCII or binary, ``x y z`` fields). At most :data:`MAX_POINTS` points:
a larger file is refused before it is read whole.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import ObstacleError
from cpr_kin.common.names import shown
from cpr_kin.common.user_files import UserFileError, read_bytes
from cpr_kin.shapes.obstacle_ranges import MAX_COORDINATE_M
from cpr_kin.shapes.ply_points import read_ply_points

FloatArray = NDArray[np.float64]

MAX_POINTS = 2_000_000
"""Most points one cloud may hold."""
MAX_CLOUD_BYTES = 100_000_000
"""Largest point-cloud file [bytes]."""
RESOLUTION_RANGE_M = (1e-3, 0.5)
"""Allowed voxel sides [m]."""
BLOCK_M = 0.25
"""Side of the blocks a cloud's voxels are split into, one obstacle each [m]."""
SUFFIXES = (".npy", ".xyz", ".txt", ".ply", ".pcd")
"""The point-cloud files :func:`read_points` reads."""


def checked_points(values: ArrayLike, what: str) -> FloatArray:
    """``(N, 3)`` finite points within :data:`MAX_COORDINATE_M`, 1 to :data:`MAX_POINTS` of them.

    Raises:
        ObstacleError: naming ``what``, the count or the first bad point.
    """
    try:
        points = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise ObstacleError(f"{what}: points must be numbers, [x, y, z] each") from None
    if points.ndim != 2 or points.shape[1] != 3:
        raise ObstacleError(f"{what}: points of shape {points.shape}; expected (N, 3), [x, y, z] each")
    if not 1 <= len(points) <= MAX_POINTS:
        raise ObstacleError(f"{what} holds {len(points)} points; 1 to {MAX_POINTS} are allowed")
    bad = ~np.isfinite(points).all(axis=1) | (np.abs(points) > MAX_COORDINATE_M).any(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise ObstacleError(
            f"{what}: point {k} = {shown(points[k].tolist())} must be finite and within "
            f"{MAX_COORDINATE_M:g} m of the cloud's frame"
        )
    return points


def checked_voxels(points: Any, resolution: Any, what: str) -> tuple[FloatArray, float]:
    """A ``voxels`` obstacle's points (:func:`checked_points`) and side; raises :class:`ObstacleError`."""
    low, high = RESOLUTION_RANGE_M
    if (
        isinstance(resolution, bool)
        or not isinstance(resolution, int | float)
        or not low <= resolution <= high
    ):
        raise ObstacleError(
            f"{what}: resolution = {shown(resolution)} must be a number in [{low:g}, {high:g}] m"
        )
    if points is None:
        raise ObstacleError(f"{what}: a voxels obstacle needs its points")
    return checked_points(points, what), float(resolution)


def voxel_centres(points: FloatArray, resolution_m: float) -> FloatArray:
    """``(M, 3)`` the centres of the cubes of side ``resolution_m`` that hold a point, sorted."""
    cells = np.unique(np.floor(points / resolution_m).astype(np.int64), axis=0)
    return np.asarray((cells + 0.5) * resolution_m)


def voxel_blocks(centres: FloatArray, block_m: float = BLOCK_M) -> list[FloatArray]:
    """The voxel centres grouped by the block of side ``block_m`` [m] that holds them, in block order."""
    blocks = np.floor(centres / block_m).astype(np.int64)
    _, inverse, counts = np.unique(blocks, axis=0, return_inverse=True, return_counts=True)
    order = np.argsort(inverse.ravel(), kind="stable")
    return [np.asarray(part) for part in np.split(centres[order], np.cumsum(counts)[:-1])]


def voxel_geometry(centres: FloatArray, resolution_m: float) -> Any:
    """A coal OcTree of the voxels of side ``resolution_m`` centred at ``centres``."""
    import coal

    return coal.makeOctree(np.ascontiguousarray(centres, dtype=float), float(resolution_m))


def read_points(path: Path) -> FloatArray:
    """The ``(N, 3)`` points of a point-cloud file (module docstring), checked.

    Raises:
        ObstacleError: a missing, too large or unreadable file, another format, bad points.
    """
    path = Path(path)
    what = f"point cloud '{path}'"
    if path.suffix.lower() not in SUFFIXES:
        raise ObstacleError(
            f"{what}: a point cloud is one of {list(SUFFIXES)} (or an OctoMap file, '.bt' or '.ot'), "
            f"not '{path.suffix}'"
        )
    try:  # the same words as for every other file a user gives
        data = read_bytes(path, MAX_CLOUD_BYTES, "point cloud")
    except UserFileError as exc:
        raise ObstacleError(str(exc)) from None
    try:
        points = _read(data, path, path.suffix.lower())
    except ObstacleError:
        raise
    except Exception as exc:  # numpy, trimesh and the parsers raise many kinds on a broken file
        raise ObstacleError(f"{what} cannot be read: {shown(f'{type(exc).__name__}: {exc}', 120)}") from None
    return checked_points(points, what)


def _read(data: bytes, path: Path, suffix: str) -> FloatArray:
    """The points of the file ``path``'s bytes ``data``, by its ``suffix``."""
    if suffix == ".npy":
        with io.BytesIO(data) as stream:  # the header's shape, before the array is made
            major, _ = np.lib.format.read_magic(stream)
            read_header = (
                np.lib.format.read_array_header_1_0 if major == 1 else np.lib.format.read_array_header_2_0
            )
            shape, _, _ = read_header(stream)
        if len(shape) != 2 or shape[1] != 3 or shape[0] > MAX_POINTS:
            raise ObstacleError(
                f"point cloud '{path}' holds an array of shape {shape}; expected (N, 3), "
                f"N at most {MAX_POINTS}"
            )
        return np.asarray(np.load(io.BytesIO(data), allow_pickle=False), dtype=float)
    if suffix in (".xyz", ".txt"):
        lines = data.decode("utf-8").splitlines()
        return np.loadtxt(lines, usecols=(0, 1, 2), ndmin=2, comments="#", max_rows=MAX_POINTS + 1)
    if suffix == ".ply":
        return read_ply_points(data, MAX_POINTS, path)
    return _read_pcd(data, path)


def _read_pcd(data: bytes, path: Path) -> FloatArray:
    """The ``x y z`` of a PCD file's bytes, ASCII or binary (``binary_compressed`` refused)."""
    header: dict[str, list[str]] = {}
    offset = 0
    while offset < len(data):
        end = data.index(b"\n", offset)
        words = data[offset:end].decode("ascii").split()
        offset = end + 1
        if words and not words[0].startswith("#"):
            header[words[0].upper()] = words[1:]
            if words[0].upper() == "DATA":
                break
    fields, count = header.get("FIELDS", []), int(header.get("POINTS", ["0"])[0])
    sizes = [int(v) for v in header.get("SIZE", [])]
    types = header.get("TYPE", [])
    counts = [int(v) for v in header.get("COUNT", ["1"] * len(fields))]
    if not {"x", "y", "z"} <= set(fields) or count > MAX_POINTS:
        raise ObstacleError(
            f"point cloud '{path}': fields {fields}, {count} points; needs x, y, z and at most {MAX_POINTS}"
        )
    kind = header.get("DATA", ["?"])[0]
    columns = [fields.index(axis) for axis in "xyz"]
    if kind == "ascii":
        values = np.loadtxt(data[offset:].decode("ascii").splitlines(), ndmin=2)
        starts = np.cumsum([0, *counts[:-1]])
        return np.asarray(values[:, [starts[c] for c in columns]], dtype=float)
    if kind != "binary":
        raise ObstacleError(f"point cloud '{path}': DATA {kind}; ascii and binary are read")
    letters = {"F": "f", "I": "i", "U": "u"}
    dtype = np.dtype(
        [
            (name, f"<{letters[t]}{s}", (c,))
            for name, t, s, c in zip(fields, types, sizes, counts, strict=True)
        ]
    )
    records = np.frombuffer(data, dtype=dtype, count=count, offset=offset)
    return np.column_stack([records[axis][:, 0] for axis in "xyz"]).astype(float)
