"""Where a URDF's mesh files are: ``package://NAME/...`` and relative paths made absolute.

A URDF names its meshes as ``package://NAME/path`` (ROS packages), as a path relative to
the URDF, or as an absolute path. :func:`resolve_mesh` finds the file, looking for the
package ``NAME``, in order:

1. the folders given (``package_dirs``): ``DIR/NAME/path``, or ``DIR/path`` when ``DIR``
   itself is the package (its name is ``NAME``);
2. the URDF's own folder tree: each folder from the URDF's up to the root, as ``DIR/NAME``
   or as the package itself (a ``description`` package's ``urdf/`` and ``meshes/`` side by
   side);
3. the installed ``example-robot-data`` (its share folder holds ``example-robot-data/``).

A ``package://`` path that leaves its package (``package://NAME/../../etc/passwd``, resolved
without following links) is refused, whatever is there.

A mesh found nowhere is a :class:`~cpr_kin.common.errors.UrdfError` naming the mesh and every
folder looked in.
"""

from __future__ import annotations

import csv
import functools
import os
import sysconfig
from collections.abc import Iterable, Sequence
from pathlib import Path

from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import shown

PACKAGE = "package://"


@functools.cache
def example_robot_data_share() -> Path | None:
    """The folder that holds the installed ``example-robot-data`` package, or ``None``.

    Read from the distribution's list of files: its wheel's ``RECORD`` where it has one (a
    thousand lines, scanned as text, where ``Distribution.files`` would make each a path).
    """
    from importlib import metadata  # its import is most of the call: here, where a URDF is loaded

    try:
        distribution = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        return None
    record = distribution.read_text("RECORD")
    if record:
        names: Iterable[str] = (row[0] for row in csv.reader(record.splitlines()) if row)
    else:
        names = (str(file) for file in distribution.files or ())
    for name in names:
        if name.endswith("example-robot-data/package.xml"):
            return Path(str(distribution.locate_file(name))).resolve().parent.parent
    return None


def installed(path: Path) -> bool:
    """Whether ``path`` lies in an installed Python distribution (site-packages): not the user's to edit."""
    resolved = Path(path).resolve()
    folders = {sysconfig.get_paths()[key] for key in ("purelib", "platlib")}
    return any(resolved.is_relative_to(Path(folder).resolve()) for folder in folders)


def check_package_dirs(urdf_path: Path, package_dirs: Sequence[Path]) -> None:
    """Refuse a folder of ``package_dirs`` that is not a folder.

    A typo would otherwise go unnoticed wherever the meshes are found elsewhere.

    Raises:
        UrdfError: naming the folder and the URDF.
    """
    for given in package_dirs:
        root = Path(given).resolve()
        if not root.is_dir():
            problem = "is not a folder" if root.exists() else "does not exist"
            raise UrdfError(
                f"package folder '{given}' (packages, for URDF '{urdf_path}') {problem}; "
                "give folders that hold the packages its package:// meshes name"
            )


def package_roots(urdf_path: Path, package_dirs: Sequence[Path] = ()) -> list[Path]:
    """The folders a ``package://`` URI is looked for in, in order (module docstring).

    Raises:
        UrdfError: a folder of ``package_dirs`` is not a folder (:func:`check_package_dirs`).
    """
    check_package_dirs(urdf_path, package_dirs)
    roots = [Path(d).resolve() for d in package_dirs]
    folder = urdf_path.resolve().parent
    roots += [folder, *folder.parents]
    share = example_robot_data_share()
    if share is not None:
        roots.append(share)
    return list(dict.fromkeys(roots))


def mesh_package_roots(
    urdf_path: Path, mesh_filenames: Iterable[str], package_dirs: Sequence[Path] = ()
) -> list[Path]:
    """:func:`package_roots` for a URDF whose meshes are ``mesh_filenames``: none where none names a package.

    The folders given are checked either way; the installed example-robot-data, found by a
    search of every installed distribution, is looked up only for a URDF that names a package.

    Raises:
        UrdfError: a folder of ``package_dirs`` is not a folder (:func:`check_package_dirs`).
    """
    if any(name.startswith(PACKAGE) for name in mesh_filenames):
        return package_roots(urdf_path, package_dirs)  # which checks the folders given
    check_package_dirs(urdf_path, package_dirs)
    return []


def resolve_mesh(filename: str, urdf_path: Path, roots: Sequence[Path]) -> Path:
    """The absolute path of the mesh a URDF names ``filename``.

    Raises:
        UrdfError: the file is nowhere the rule looks (module docstring).
    """
    if not filename.startswith(PACKAGE):
        path = Path(filename.removeprefix("file://"))
        path = path if path.is_absolute() else urdf_path.resolve().parent / path
        if path.is_file():
            return path
        raise UrdfError(f"URDF '{urdf_path}': mesh '{filename}' does not exist (looked for '{path}')")
    name, _, inside = filename.removeprefix(PACKAGE).partition("/")
    if os.path.normpath(inside).split(os.sep)[0] == os.pardir or Path(inside).is_absolute():
        raise UrdfError(
            f"URDF '{urdf_path}': mesh {shown(filename, 120)} leaves its package '{name}' "
            "(a package:// path names a file inside the package); fix the path"
        )
    candidates = []
    for root in roots:
        candidates.append(root / name / inside)
        if root.name == name:
            candidates.append(root / inside)
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    looked = ", ".join(f"'{root}'" for root in roots[:6]) + (", ..." if len(roots) > 6 else "")
    raise UrdfError(
        f"URDF '{urdf_path}': mesh '{filename}' not found: package '{name}' is in none of {looked}; "
        "give its folder (--package-dir, or package_dirs=...)"
    )


EXAMPLE_ROBOTS = {
    "panda": "panda_description/urdf/panda.urdf",
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "so100": "so_arm_description/urdf/so100.urdf",
    "so101": "so_arm_description/urdf/so101.urdf",
    "xarm7": "xarm_description/urdf/xarm7.urdf",
    "z1": "z1_description/urdf/z1.urdf",
}
"""Arms of example-robot-data a scene may name (``robot: panda``), by their URDF in it."""


def example_robot(name: str) -> Path:
    """The URDF of the example-robot-data arm ``name`` (:data:`EXAMPLE_ROBOTS`).

    Raises:
        UrdfError: an unknown name, or example-robot-data not installed.
    """
    if name not in EXAMPLE_ROBOTS:
        raise UrdfError(f"robot '{name}' is not one of example-robot-data's arms {sorted(EXAMPLE_ROBOTS)}")
    share = example_robot_data_share()
    if share is None:
        raise UrdfError(
            f"robot '{name}' needs example-robot-data: pip install example-robot-data (the 'robots' extra)"
        )
    return share / "example-robot-data" / "robots" / EXAMPLE_ROBOTS[name]
