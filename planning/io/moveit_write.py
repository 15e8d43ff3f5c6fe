"""Writing a converted MoveIt problem: the scene file and its meshes, all or nothing.

The meshes go to ``<stem>_meshes/`` beside the scene file, an octomap's tree to
``<stem>_octomap.bt`` (or ``.ot``); every path is made relative to
the scene file. Nothing is written over an input, and a scene that is refused or cannot be
written leaves no mesh behind.
"""

from __future__ import annotations

import contextlib
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import trimesh

from cpr_kin.common.user_files import dump_yaml
from planning.io.moveit_import import ImportedScene
from planning.io.output_paths import check_not_inputs
from planning.io.publish import write_file


def write_imported(
    imported: ImportedScene,
    out: Path,
    inputs: Mapping[str, Path | None] | None = None,
    source: str = "the converted scene",
) -> Path:
    """Write the scene file ``out`` and its meshes (``<stem>_meshes/``), paths relative to ``out``.

    The scene is validated (:func:`~planning.io.scene_file.parse_scene`) before its file is
    written; if it is refused, the meshes written for it are removed and nothing is left.

    Args:
        imported: the converted problem.
        out: the scene file to write.
        inputs: the files the conversion read, by what they are: none may be overwritten.
        source: what the scene was converted from, for a refusal's message.

    Raises:
        OutputError: ``out`` or one of its meshes is one of ``inputs``.
        SceneError: the converted scene is not a valid scene.
    """
    from planning.io.scene_file import parse_scene

    out = Path(out)
    folder = out.parent.resolve()
    document = dict(imported.document)

    def relative(path: str) -> str:
        return os.path.relpath(path, folder)

    robot = dict(document["robot"])
    for key in ("urdf", "srdf", "limits"):
        if key in robot:
            robot[key] = relative(robot[key])
    if "packages" in robot:
        robot["packages"] = [relative(p) for p in robot["packages"]]
    document["robot"] = robot
    mesh_folder = f"{out.stem}_meshes"

    def in_folder(shape: dict[str, Any]) -> dict[str, Any]:
        if shape["shape"] == "point_cloud":  # an octomap's tree, beside the scene
            return {**shape, "file": f"{out.stem}_{shape['file']}"}
        return {**shape, "mesh": f"{mesh_folder}/{shape['mesh']}"} if shape["shape"] == "mesh" else shape

    document["obstacles"] = [in_folder(obstacle) for obstacle in document["obstacles"]]
    if "payload" in document:
        document["payload"] = {**document["payload"], "shape": in_folder(document["payload"]["shape"])}
    others = {folder / f"{out.stem}_{file}": content for file, content in imported.files.items()}
    check_not_inputs([out, *(folder / mesh_folder / file for file in imported.meshes), *others], inputs or {})
    written: list[Path] = []
    try:
        for path, content in others.items():
            written.append(write_file(path, content))
        for file, mesh in imported.meshes.items():
            written.append(
                write_file(folder / mesh_folder / file, bytes(trimesh.exchange.stl.export_stl(mesh)))
            )
        parse_scene(document, source=source, base=folder)
        return write_file(out, dump_yaml(document, width=100))
    except BaseException:  # refused, unwritable or interrupted: no mesh is left without its scene
        for path in written:
            path.unlink(missing_ok=True)
        with contextlib.suppress(OSError):  # only if empty: a folder of the user's own stays
            (folder / mesh_folder).rmdir()
        raise
