"""A scene file's ``robot:`` entry: a name, a URDF path, or a mapping, to and from :class:`cpr_kin.RobotSpec`.

- a name: ``cpr``, the bundled CPR preset (:data:`BUNDLED`), or one of example-robot-data's arms
  (``robot: panda``, :data:`cpr_kin.model.packages.EXAMPLE_ROBOTS`);
- a URDF path, relative to the scene file (``robot: ../urdf/my_arm.urdf``): the CPR preset
  for a URDF with the CPR's joints, else the generic rules (:func:`cpr_kin.robot_spec`);
- a mapping ``{urdf, srdf, packages, limits, joints, tcp, fixed}``: ``urdf`` as above (a
  path or a name), ``srdf`` and ``limits`` paths, ``packages`` folders holding the packages
  its ``package://`` meshes name, ``joints`` the planned joints, ``tcp`` the tool frame,
  ``fixed`` the values of held joints ``{joint: value}``. Paths are relative to the scene
  file.

No ``robot:`` is the CPR (:func:`default_robot`): the default is chosen here, where a scene
file is read, and a scene of that robot is written without the entry. The scene holds
absolute paths; :func:`robot_entry` writes a spec back in the mapping form.
"""

import dataclasses
from pathlib import Path
from typing import Annotated, Any

from pydantic import Field, Tag

import cpr_kin as ck
from cpr_kin.common.names import escaped
from cpr_kin.description.urdf_file import check_urdf_file
from cpr_kin.model.packages import EXAMPLE_ROBOTS, example_robot
from planning.io.schema_types import (
    BY_KIND,
    MAPPING_TAG,
    OTHER_TAG,
    Angle,
    FilePath,
    Name,
    Strict,
    empty_list,
)

BUNDLED = "cpr"
"""The name of the bundled robot, the CPR preset: wherever a robot is named (a scene's
``robot:``, its ``urdf:``, ``cpr-plan robot-info cpr``, ``--urdf cpr``)."""


class RobotMapping(Strict):
    """``robot: {urdf, srdf, packages, limits, joints, tcp, fixed}`` (module docstring)."""

    urdf: FilePath
    srdf: FilePath | None = None
    packages: Annotated[list[FilePath], Field(max_length=64)] = Field(default_factory=empty_list)
    limits: FilePath | None = None
    joints: Annotated[list[Name], Field(min_length=1, max_length=64)] | None = None
    tcp: Name | None = None
    fixed: Annotated[dict[Name, Angle], Field(max_length=64)] = Field(default_factory=dict)


RobotEntry = Annotated[
    Annotated[FilePath, Tag(OTHER_TAG)] | Annotated[RobotMapping, Tag(MAPPING_TAG)], BY_KIND
]
"""A scene's ``robot:``: a name or URDF path, or a :class:`RobotMapping`."""


def _urdf(value: str, base: Path) -> Path:
    """A URDF named by ``value``: the bundled one, an example-robot-data arm, or a path relative to ``base``.

    Raises:
        UrdfError: no such arm, and no such file (or not a regular file); read when it loads.
    """
    if value == BUNDLED:
        return ck.cpr_spec().urdf
    if value in EXAMPLE_ROBOTS:
        return example_robot(value)
    path = (base / value).resolve()
    if not path.exists() and not path.suffix:
        from difflib import get_close_matches  # a message's, not every scene's (start-up)

        close = get_close_matches(value.lower(), [BUNDLED, *sorted(EXAMPLE_ROBOTS)], n=1, cutoff=0.6)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        raise ck.UrdfError(
            f"'{escaped(value)}' is neither a URDF file ('{path}' does not exist), the bundled "
            f"'{BUNDLED}', nor one of example-robot-data's arms {sorted(EXAMPLE_ROBOTS)}{hint}"
        )
    check_urdf_file(path)
    return path


def default_robot() -> "ck.RobotSpec":
    """The robot of a scene file without ``robot:``: the CPR preset (:func:`cpr_kin.cpr_spec`)."""
    return ck.cpr_spec()


def robot_spec_of(entry: str | RobotMapping | None, base: Path) -> "ck.RobotSpec":
    """The :class:`cpr_kin.RobotSpec` of a ``robot:`` entry (module docstring); none: the default."""
    if entry is None:
        return default_robot()
    if isinstance(entry, str):
        return ck.robot_spec(_urdf(entry, base))
    spec = ck.robot_spec(_urdf(entry.urdf, base))
    changes: dict[str, Any] = {
        "srdf": None if entry.srdf is None else (base / entry.srdf).resolve(),
        "limits": None if entry.limits is None else (base / entry.limits).resolve(),
        "package_dirs": tuple((base / d).resolve() for d in entry.packages),
        "held": tuple(entry.fixed.items()),
    }
    if entry.joints is not None:
        changes["joints"] = tuple(entry.joints)
    if entry.tcp is not None:
        changes["tcp"] = entry.tcp
    return dataclasses.replace(spec, **{k: v for k, v in changes.items() if v not in (None, ())})


def robot_entry(spec: "ck.RobotSpec") -> dict[str, Any]:
    """The mapping form of ``spec``, with the keys that differ from what its URDF alone gives."""
    entry: dict[str, Any] = {"urdf": str(spec.urdf)}
    plain = ck.robot_spec(spec.urdf)
    if spec.srdf is not None:
        entry["srdf"] = str(spec.srdf)
    if spec.package_dirs:
        entry["packages"] = [str(d) for d in spec.package_dirs]
    if spec.limits is not None:
        entry["limits"] = str(spec.limits)
    if spec.joints != plain.joints and spec.joints is not None:
        entry["joints"] = list(spec.joints)
    if spec.tcp != plain.tcp and spec.tcp is not None:
        entry["tcp"] = spec.tcp
    if spec.held:
        entry["fixed"] = dict(spec.held)
    return entry
