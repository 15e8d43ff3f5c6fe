"""A PlanningScene's octomap as a point-cloud obstacle: the tree, as an OctoMap file beside the scene.

MoveIt keeps what its sensors see in ``world.octomap`` (``octomap_msgs/OctomapWithPose``): the
tree's bytes (``binary: true``: OctoMap's ``.bt`` encoding, else ``.ot``), its resolution, and
the pose of its frame (``origin`` in ``header.frame_id``, a frame fixed to the world). The
import writes the bytes under OctoMap's own header, so the file opens in OctoMap's tools too,
and the scene names it as a ``point_cloud`` obstacle placed at that pose. The tree is read
before anything is written (:mod:`cpr_kin.shapes.octree_files`): a broken one is refused naming the
field.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cpr_kin.common.errors import ObstacleError
from cpr_kin.shapes.octree_files import octree_voxels
from cpr_kin.shapes.point_clouds import RESOLUTION_RANGE_M
from planning.io.moveit_frames import Frames
from planning.io.moveit_messages import MoveItImportError, OctomapWithPose
from planning.io.moveit_objects import placement

OCTOMAP_NAME = "octomap"
"""The obstacle's name in the scene, and its file's stem."""


@dataclass(frozen=True)
class ConvertedOctomap:
    """An octomap as a scene's obstacle.

    Attributes:
        entry: the obstacle entry; its ``file`` is a key of ``files``.
        files: the OctoMap file to write beside the scene, by file name.
    """

    entry: dict[str, Any]
    files: dict[str, bytes]


def convert_octomap(message: OctomapWithPose, frames: Frames, ignored: list[str]) -> ConvertedOctomap | None:
    """The octomap's obstacle, or ``None`` for a map with no data or no occupied voxel (noted in ``ignored``).

    Raises:
        MoveItImportError: a broken tree, another tree type, a resolution outside the scene's
            range, a frame that moves or is unknown.
    """
    tree, where = message.octomap, "scene.world.octomap"
    if not tree.data:
        return None
    data = bytes(value & 0xFF for value in tree.data)
    low, high = RESOLUTION_RANGE_M
    if not low <= tree.resolution <= high:
        raise MoveItImportError(
            f"{where}.octomap.resolution = {tree.resolution:g} m; a scene's voxels are {low:g} to {high:g} m"
        )
    try:
        voxels = octree_voxels(data, tree.resolution, tree.binary, f"{where}.octomap", tree.id or "OcTree")
    except ObstacleError as exc:
        raise MoveItImportError(str(exc)) from None
    if not len(voxels.centres):
        ignored.append(f"{where}: a tree without an occupied voxel")
        return None
    frame_in_base = frames.pose(message.header.frame_id, f"{where}.header.frame_id") @ message.origin.matrix()
    kind, suffix = ("binary ", ".bt") if tree.binary else ("", ".ot")
    header = (
        f"# Octomap OcTree {kind}file\nid OcTree\nsize {voxels.node_count}\nres {tree.resolution!r}\ndata\n"
    )
    file = OCTOMAP_NAME + suffix
    entry = {"name": OCTOMAP_NAME, "shape": "point_cloud", "file": file, **placement(frame_in_base)}
    return ConvertedOctomap(entry=entry, files={file: header.encode("ascii") + data})
