"""Reading a URDF file: strict, bounded XML, and yourdfpy's structural validation.

Pinocchio builds the models from the file (:meth:`cpr_kin.Robot.load`); this module makes
sure first that the file is one: a regular file of bounded size, well-formed XML parsed
without entity expansion or network access, and (for a user's URDF) a structure yourdfpy
accepts, so that a broken file gets a message naming the problem.
"""

from __future__ import annotations

import copy
import hashlib
import io
import math
import re
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lxml import etree

from cpr_kin.common.disk_cache import cached_json
from cpr_kin.common.errors import UrdfError
from cpr_kin.common.names import escaped
from cpr_kin.model.packages import resolve_mesh

MAX_URDF_BYTES = 10_000_000
"""Largest URDF file [bytes] (the CPR's takes 6 kB)."""
SHAPE_SIZES = {"box": (("size", 3),), "cylinder": (("radius", 1), ("length", 1)), "sphere": (("radius", 1),)}
"""The size attributes of each URDF shape, each with how many numbers it holds."""


def check_urdf_file(path: Path) -> None:
    """Raise :class:`UrdfError` unless ``path`` is a regular file (what a scene's ``robot:`` checks first)."""
    if not path.exists():
        raise UrdfError(f"URDF file '{path}' does not exist; pass the path of a .urdf file")
    if not path.is_file():
        raise UrdfError(f"URDF file '{path}' is not a regular file (a folder or a device)")


DECLARED_VERSION = re.compile(rb"""\A(\xef\xbb\xbf)?(\s*<\?xml\s+version\s*=\s*)(["'])([^"']*)\3""")
"""The version an XML declaration opens with (after a byte-order mark, if any)."""


def as_xml_1_0(data: bytes) -> bytes:
    """``data`` with an XML declaration's version other than ``1.x`` read as ``1.0``.

    Many URDFs (pybullet's Minitaur and WSG-50 gripper among them) declare ``version="0.0"``,
    which libxml2 refuses while urdfdom, Pinocchio's parser, and yourdfpy read them as XML 1.0.
    """
    declared = DECLARED_VERSION.match(data)
    if declared is None or re.fullmatch(rb"1\.[0-9]+", declared.group(4)):
        return data
    quote = declared.group(3)
    return data[: declared.start(4)] + b"1.0" + quote + data[declared.end() :]


def parse_urdf(path: Path) -> etree._ElementTree:
    """Parse ``path`` as strict XML; raise :class:`UrdfError` if it is missing or malformed.

    Entities are not expanded and nothing is fetched from the network: a URDF that defines
    entities (an "XML bomb", or a reference to a local file) is parsed as written. A
    declaration of another XML version than 1.x is read as 1.0 (:func:`as_xml_1_0`).
    """
    check_urdf_file(path)
    if path.stat().st_size > MAX_URDF_BYTES:
        raise UrdfError(f"URDF file '{path}' has {path.stat().st_size} bytes; at most {MAX_URDF_BYTES}")
    parser = etree.XMLParser(recover=False, resolve_entities=False, no_network=True, huge_tree=False)
    try:
        tree = etree.parse(io.BytesIO(as_xml_1_0(path.read_bytes())), parser, base_url=str(path))
    except etree.XMLSyntaxError as exc:
        message = str(exc) if len(str(exc)) <= 120 else str(exc)[:117] + "..."
        raise UrdfError(f"URDF file '{path}' is not well-formed XML: {message}") from None
    root = tree.getroot()  # a named robot with links, or the parsers' complaints name neither file nor fix
    if root.tag != "robot":
        raise UrdfError(
            f"URDF file '{path}' has root element <{root.tag}>; a URDF's root is <robot name=...>"
        )
    if root.find("link") is None and root.find("group") is not None:
        raise UrdfError(
            f"URDF file '{path}' holds <group>s and no <link>: it is an SRDF; give the robot's URDF"
        )
    macros = sorted(
        {e.tag.split("}")[-1] for e in root.iter() if isinstance(e.tag, str) and "xacro" in e.tag}
    )
    if macros:
        raise UrdfError(
            f"URDF file '{path}' is a xacro file (it holds <xacro:{macros[0]}>); expand it into a URDF "
            f"first: xacro {path.name} > {path.stem}_expanded.urdf (pip install xacro)"
        )
    for element in root.iter():
        unexpanded = [v for v in element.attrib.values() if "$(" in v or "${" in v]
        if unexpanded:
            raise UrdfError(
                f"URDF file '{path}' line {element.sourceline} holds a xacro substitution left unexpanded "
                f"('{escaped(unexpanded[0][:60])}'); expand it into a URDF first: xacro {path.name} > "
                f"{path.stem}_expanded.urdf (pip install xacro)"
            )
    if root.find("link") is None:
        raise UrdfError(
            f"URDF file '{path}' has no <link>: an empty robot; a URDF "
            "written by xacro without its arguments can be (run xacro with them)"
        )
    if not root.get("name"):
        raise UrdfError(
            f"URDF file '{path}': <robot> has no name attribute; the URDF specification requires one"
        )
    return tree


SPEC_OPTIONAL = frozenset(
    f"Tag <limit> of joint is missing attribute '{bound}'." for bound in ("lower", "upper")
)
"""yourdfpy's complaints about what the URDF specification makes optional: a revolute or
prismatic joint's ``lower`` and ``upper`` default to 0 (as urdfdom, Pinocchio's parser, reads
them); a planned joint with such a range is refused by its own check, naming the joint."""


def validate_urdf(path: Path) -> None:
    """Validate the URDF at ``path`` with yourdfpy; raise :class:`UrdfError` naming the problems.

    yourdfpy is imported here, not with the package: it imports trimesh, about 0.7 s of every
    new process. The verdict depends only on the file's bytes and yourdfpy's version, so a
    file found valid is remembered by their digest (:mod:`cpr_kin.common.disk_cache`) and
    not validated again; an invalid one is, every time, and its message shown.
    """
    content = path.read_bytes()
    digest = hashlib.sha256(b"urdf-valid-1 " + _yourdfpy_version().encode() + b" " + content).hexdigest()
    cached_json("urdf-valid", digest, lambda: _validated(path, content))


def _yourdfpy_version() -> str:
    """The installed version of yourdfpy, read without importing it ("" if it cannot be read)."""
    from importlib import metadata  # here: a file found valid before is the one call that needs it

    try:
        return metadata.version("yourdfpy")
    except metadata.PackageNotFoundError:
        return ""


def _validated(path: Path, content: bytes) -> dict[str, bool]:
    """Validate the URDF ``content`` of ``path`` with yourdfpy (:func:`validate_urdf`): ``{"valid": True}``.

    The bytes whose digest keys the verdict, not the file read again (it may have changed since).
    """
    import yourdfpy

    try:
        with warnings.catch_warnings():  # trimesh's arithmetic on a value that is then refused, by name
            warnings.simplefilter("ignore", RuntimeWarning)
            source = io.BytesIO(as_xml_1_0(content))  # yourdfpy refuses XML version '0.0' too
            unbuilt = dict.fromkeys(("build_scene_graph", "load_meshes", "load_collision_meshes"), False)
            urdf = yourdfpy.URDF.load(source, mesh_dir=str(path.parent), **unbuilt)
    except Exception as exc:  # yourdfpy raises bare exceptions on structural problems
        raise UrdfError(f"URDF file '{path}' cannot be read ({type(exc).__name__}: {exc})") from None
    found: list[Any] = []

    def keep(errors: list[Any]) -> bool:
        found.extend(e for e in errors if getattr(e, "msg", None) not in SPEC_OPTIONAL)
        return not found

    if not urdf.validate(keep):
        problems = "; ".join(str(e) for e in found)
        raise UrdfError(f"URDF file '{path}' is invalid: {problems}")
    return {"valid": True}


TURN_EITHER_WAY_RAD = 2 * math.pi
"""How far either way a ``revolute`` joint is planned [rad]: a wider range (an industrial
wrist's +-400 degrees, a leg's +-10 rad, a URDF's +-1e9 for "no limit") is planned within
``[-2 pi, 2 pi]``, one turn either way as UR and xArm arms have, for the reason a continuous
joint's is bounded (:func:`narrowed_ranges`)."""
CONTINUOUS_RANGE_RAD = TURN_EITHER_WAY_RAD
"""The range a ``continuous`` joint is planned within: ``[-2 pi, 2 pi]`` rad, one turn either
way. A continuous joint turns without end; a plan between two poses never needs more than half
a turn of it, and a bounded range keeps the search's box and the trajectories bounded. Within
one turn either way, a goal's IK solution is turned by whole turns towards the start
(:func:`~cpr_kin.kinematics.numerical_ik.turned_towards`), so a motion across +-pi goes the
short way: within ``[-pi, pi]`` a turn of 0.3 rad across it took 6 rad."""
RANGE_TOLERANCE_RAD = 1e-3
"""How far a revolute range may pass one turn and count as within it (a URDF that writes
2 pi as 6.2832) [rad]."""


def narrowed_ranges(tree: etree._ElementTree) -> dict[str, tuple[float, float]]:
    """The revolute joints whose range passes :data:`TURN_EITHER_WAY_RAD`, with their URDF ranges [rad].

    Each is planned within its range's part within one turn either way. A range with no such
    part (``[7, 10]`` rad) is not narrowed: the loader refuses it, naming it
    (:func:`cpr_kin.description.supported.check_limits`).
    """
    bound, narrowed = TURN_EITHER_WAY_RAD + RANGE_TOLERANCE_RAD, {}
    for joint in tree.getroot().findall("joint"):
        limit = joint.find("limit")
        if joint.get("type") != "revolute" or limit is None:
            continue
        try:
            lower, upper = float(limit.get("lower", "0")), float(limit.get("upper", "0"))
        except ValueError:  # refused by name where the URDF is checked
            continue
        if (lower < -bound or upper > bound) and max(lower, -bound) < min(upper, bound):
            narrowed[joint.get("name", "")] = (lower, upper)
    return narrowed


def numbers_in(text: str | None, count: int) -> list[float] | None:
    """``count`` numbers written in ``text``, or ``None`` where it holds anything else."""
    try:
        values = [float(v) for v in (text or "").split()]
    except ValueError:
        return None
    return values if len(values) == count else None


def draws_nothing(visual: etree._Element) -> bool:
    """Whether a ``<visual>``'s shape has no area: a sphere or cylinder of radius 0, a box of two sides 0.

    pybullet's Laikago gives its toes visual spheres of radius 0. A box of one side 0 (a plate)
    and a cylinder of length 0 (a disc) are drawn.
    """
    for shape in visual.iterfind("geometry/*"):
        if shape.tag in ("sphere", "cylinder"):
            radius = numbers_in(shape.get("radius"), 1)
            if radius == [0.0]:
                return True
        elif shape.tag == "box" and (numbers_in(shape.get("size"), 3) or []).count(0.0) >= 2:
            return True
    return False


def prepared_xml(tree: etree._ElementTree, path: Path, roots: Sequence[Path]) -> str:
    """The URDF's text as the models are built from it.

    Every ``continuous`` joint becomes a ``revolute`` one within
    :data:`CONTINUOUS_RANGE_RAD` (its velocity and effort kept; where the URDF gives none, as
    its specification allows for a continuous joint, they are 0: unknown, so that a planned
    joint without a velocity limit is refused by name at load, naming the two places to give
    one, while a joint the planner only holds, such as a mobile base's caster wheel, loads),
    a revolute range beyond one turn either way is narrowed to it (:func:`narrowed_ranges`),
    a visual that draws nothing (:func:`draws_nothing`) is left out, and every mesh file name
    is made absolute (:func:`cpr_kin.model.packages.resolve_mesh`), so
    that a missing mesh is named before Pinocchio reads anything.

    Raises:
        UrdfError: a mesh not found.
    """
    root = copy.deepcopy(tree.getroot())
    narrowed = narrowed_ranges(tree)
    for joint in root.findall("joint"):
        name, limit = joint.get("name", ""), joint.find("limit")
        if name in narrowed and limit is not None and joint.get("type") == "revolute":
            lower, upper = narrowed[name]
            limit.set("lower", repr(max(lower, -TURN_EITHER_WAY_RAD)))
            limit.set("upper", repr(min(upper, TURN_EITHER_WAY_RAD)))
        if joint.get("type") != "continuous":
            continue
        joint.set("type", "revolute")
        limit = joint.find("limit")
        if limit is None:
            limit = etree.SubElement(joint, "limit")
        for unknown in ("velocity", "effort"):
            if limit.get(unknown) is None:
                limit.set(unknown, "0")
        limit.set("lower", repr(-CONTINUOUS_RANGE_RAD))
        limit.set("upper", repr(CONTINUOUS_RANGE_RAD))
    for link in root.findall("link"):
        for visual in link.findall("visual"):
            if draws_nothing(visual):
                link.remove(visual)
    for mesh in root.iter("mesh"):
        filename = mesh.get("filename")
        if filename:
            mesh.set("filename", str(resolve_mesh(filename, path, roots)))
    return str(etree.tostring(root, encoding="unicode"))


def mesh_filenames(tree: etree._ElementTree) -> list[str]:
    """The file names of the URDF's meshes, as it gives them (``package://...``, relative or absolute)."""
    return [mesh.get("filename") or "" for mesh in tree.iter("mesh")]


def massless_links(tree: etree._ElementTree, model: Any) -> tuple[str, ...]:
    """Links that a planned joint of ``model`` moves which have a shape but no ``<inertial>``."""
    import pinocchio as pin  # the model is Pinocchio's; reading a URDF alone needs none

    links = tree.getroot().findall("link")
    weighed = {link.get("name") for link in links if link.find("inertial") is not None}
    shaped = {
        link.get("name")
        for link in links
        if link.find("collision") is not None or link.find("visual") is not None
    }
    moved = {
        frame.name for frame in model.frames if frame.type == pin.FrameType.BODY and frame.parentJoint > 0
    }
    return tuple(sorted((moved & shaped) - weighed))
