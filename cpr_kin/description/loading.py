"""Any serial robot from its URDF: :class:`RobotSpec` says what to load, :func:`load_robot` loads it.

Loading, in order:

1. the URDF is read as strict XML, validated by yourdfpy (but a preset's bundled file, which
   the tests validate), and checked for what the planner supports (:mod:`cpr_kin.description.supported`);
2. its mesh paths (``package://NAME/...``, relative, absolute) are resolved
   (:mod:`cpr_kin.model.packages`), its ``continuous`` joints bounded and its revolute ranges
   beyond one turn either way narrowed to it (:func:`~cpr_kin.description.urdf_file.prepared_xml`,
   listed in :attr:`Robot.ranges_narrowed`);
3. Pinocchio builds the kinematic, collision and visual models (what its URDF parser prints
   stays off the terminal);
4. the joints that are not planned are held: at the value given in ``held``, a ``mimic``
   joint at ``multiplier x leader + offset`` of its (held) leader, a ``planar`` or ``floating``
   joint (a mobile base's) at its identity pose, any other at 0 clipped into its range
   (:mod:`cpr_kin.description.joint_roles`); Pinocchio's reduced model keeps the planned joints only;
5. velocity limits come from the URDF, acceleration and jerk limits from the limits file
   (given, or found beside the URDF, :func:`~cpr_kin.model.limits.find_limits_file`), the
   documented defaults where it gives none (:func:`~cpr_kin.model.limits.default_limits`, listed in
   :attr:`Robot.limits_defaulted`);
6. every mesh of the collision model becomes its convex hull, which contains it (a clearance
   to the hull is at most the clearance to the mesh: safe) and gives coal signed distances;
   where a hull reaches beyond its mesh by more than a millimetre, the mesh is kept and decides
   wherever the hull comes within a margin (:mod:`cpr_kin.shapes.exact_meshes`);
7. the collision geometries form two groups: ``effector`` (the links given, by default those
   the last planned joint before the tool frame moves alone, or the nearest joint above it
   whose links have collision geometry) and ``links`` (the rest).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from lxml import etree

from cpr_kin.bounds.close_pairs import close_pairs
from cpr_kin.bounds.overlapping_pairs import overlapping_pairs
from cpr_kin.collision.srdf_pairs import SrdfPairs, find_srdf, read_srdf, self_pairs
from cpr_kin.description.joint_roles import base_joints, held_values, planned_joints
from cpr_kin.description.resources import makers_limits_path
from cpr_kin.description.robot_options import check_not_one_name, check_options, check_tcp
from cpr_kin.description.supported import check_limits, checked_urdf
from cpr_kin.description.urdf_file import massless_links, mesh_filenames, narrowed_ranges, prepared_xml
from cpr_kin.description.urdf_models import VisualModel, build_models, convex_hulls, reduced_models
from cpr_kin.model.arm import ArmChain, arm_chain
from cpr_kin.model.geometry_groups import carried_alone, grouped_geometries
from cpr_kin.model.limits import LIMITS_NAMES, JointLimits, find_limits_file, read_dynamic_limits
from cpr_kin.model.packages import mesh_package_roots
from cpr_kin.model.robot import PositionIk, Robot, joint_units


@dataclass(frozen=True)
class RobotSpec:
    """What robot to load, from which files; hashable (a batch worker loads each spec once).

    Attributes:
        urdf: the URDF file.
        srdf: its SRDF, whose ``disable_collisions`` the self-collision checks leave out;
            default: found by :func:`~cpr_kin.collision.srdf_pairs.find_srdf` (``<urdf name>.srdf``
            or ``<robot name>.srdf`` beside the URDF or in ``robot_description/srdf/``).
        package_dirs: folders that hold the packages its ``package://`` meshes name.
        limits: its acceleration and jerk limits file; default: found beside the URDF by
            ``limits_names``, else ``default_limits``, else a maker's file shipped for the
            URDF's robot name (:func:`cpr_kin.description.resources.makers_limits_path`), else the
            documented defaults.
        joints: the planned joints, in configuration order; default: those from the root
            to ``tcp`` when it is named, else the arm's (:func:`arm_chain`: from the root
            until the tree branches, as a hand into its fingers), but mimic joints. The
            others are held.
        tcp: the tool-centre-point frame (a link or joint name); default: ``tcp`` if the URDF
            has one, else the arm's tool link (:func:`arm_chain`).
        held: ``(joint, value)`` pairs of held joints [rad or m].
        effector_links: links of the ``effector`` collision group; default: module docstring.
        wrist_joints: joints a plan holds unless its start and goal differ in them (and a
            ``tcp`` goal at 0 unless it names them).
        position_ik: a preset's IK of a tool position (:class:`~cpr_kin.model.robot.PositionIk`).
        limits_names: the limits file names looked for beside the URDF.
        default_limits: the limits file used when none is found beside the URDF.
        default_srdf: the SRDF used when none is given or found (a preset's).
        validate: validate the URDF with yourdfpy (a preset skips its own bundled file).
    """

    urdf: Path
    srdf: Path | None = None
    package_dirs: tuple[Path, ...] = ()
    limits: Path | None = None
    joints: tuple[str, ...] | None = None
    tcp: str | None = None
    held: tuple[tuple[str, float], ...] = ()
    effector_links: tuple[str, ...] | None = None
    wrist_joints: tuple[str, ...] = ()
    position_ik: PositionIk | None = None
    limits_names: tuple[str, ...] = LIMITS_NAMES
    default_limits: Path | None = None
    default_srdf: Path | None = None
    validate: bool = field(default=True, compare=False)

    def __post_init__(self) -> None:
        check_options(self)

    def load(self) -> Robot:
        """The robot (module docstring)."""
        path = Path(self.urdf)
        tree = checked_urdf(path, self.validate)
        xml = prepared_xml(tree, path, mesh_package_roots(path, mesh_filenames(tree), self.package_dirs))
        arm = arm_chain(tree)
        model, collision = build_models(xml, path)
        check_tcp(self.tcp, model, path)
        bases = base_joints(tree)
        planned = planned_joints(self.joints, self.tcp, model, tree, path, arm, bases)
        held = held_values(dict(self.held), model, tree, planned + bases, path)
        visual = VisualModel(xml, path)
        if held or bases:
            lock = [model.getJointId(name) for name in (*held, *bases)]
            q_ref = pin.neutral(model)
            for name, value in held.items():
                q_ref[model.joints[model.getJointId(name)].idx_q] = value
            model, (collision,) = reduced_models(model, [collision], lock, q_ref)
            visual = VisualModel(xml, path, tuple(lock), tuple(q_ref))
        names = tuple(model.names[1:])
        tcp = self._tcp_frame(model, arm)
        velocity = np.array(model.velocityLimit, dtype=float)
        known = tuple(j.get("name", "") for j in tree.getroot().findall("joint"))
        limits_file = (
            self.limits
            or find_limits_file(path, self.default_limits, self.limits_names)
            or makers_limits_path(tree.getroot().get("name", ""), known)
        )
        dynamic = read_dynamic_limits(limits_file, names, velocity, known, path)
        if dynamic.velocity is not None:  # the file's, where the URDF gives none
            velocity = dynamic.velocity
            model.velocityLimit = velocity
        limits = JointLimits(
            names=names,
            lower=np.array(model.lowerPositionLimit, dtype=float),
            upper=np.array(model.upperPositionLimit, dtype=float),
            velocity=velocity,
            acceleration=dynamic.acceleration,
            jerk=dynamic.jerk,
            effort=np.array(model.effortLimit, dtype=float),
        )
        check_limits(limits, joint_units(model), path)
        meshes = convex_hulls(collision)
        srdf = self.srdf or find_srdf(path, tree.getroot().get("name")) or self.default_srdf
        links = {f.name for f in model.frames}
        srdf_pairs = read_srdf(srdf, links) if srdf is not None else SrdfPairs(frozenset())
        effector = (
            set(self.effector_links)
            if self.effector_links is not None
            else carried_alone(model, collision, tcp)
        )
        geometries = grouped_geometries(model, collision, collision_names(tree), effector, path)
        checked = self_pairs(model, collision, srdf_pairs.disabled)
        overlapping = overlapping_pairs(model, collision, checked)
        kept = tuple(pair for pair in checked if pair not in overlapping)
        exact = {}
        if meshes:  # links given as meshes: where their hulls exceed them, the meshes decide
            from cpr_kin.shapes.exact_meshes import exact_meshes

            exact = exact_meshes(meshes)
        return Robot(
            urdf_path=path,
            model=model,
            collision_model=collision,
            build_visual_model=visual,
            limits=limits,
            geometries=geometries,
            _data=model.createData(),
            tcp_frame=tcp,
            wrist_joints=self.wrist_joints,
            position_ik=self.position_ik,
            limits_path=dynamic.source,
            limits_defaulted=dynamic.defaulted,
            ranges_narrowed={n: r for n, r in narrowed_ranges(tree).items() if n in names},
            held=held,
            base_joints=bases,
            srdf_path=srdf,
            self_pairs=kept,
            overlapping_links=tuple(
                dict.fromkeys((geometries[a].link, geometries[b].link) for a, b in overlapping)
            ),
            close_pairs=close_pairs(model, collision, kept, [g.link for g in geometries], meshes=exact),
            srdf_unknown_links=srdf_pairs.unknown_links,
            massless_links=massless_links(tree, model),
            capsule_meshes=tuple(collision.geometryObjects[m.geometry].name for m in meshes if not m.hull),
            exact_meshes=exact,
        )

    def _tcp_frame(self, model: Any, arm: ArmChain) -> str:
        """The tool-centre-point frame (attribute ``tcp``, checked by :func:`check_tcp`)."""
        if self.tcp is not None:
            return self.tcp
        if model.existFrame("tcp"):
            return "tcp"
        return arm.tool


def load_robot(urdf_path: str | Path, **options: Any) -> Robot:
    """Load the robot of ``urdf_path``: ``RobotSpec(urdf_path, **options).load()``.

    Raises:
        UrdfError: a missing, malformed or unsupported URDF, a mesh not found, an unknown
            planned or held joint, a limits file that does not fit.
    """
    for key in (k for k in ("srdf", "limits", "default_limits") if options.get(k) is not None):
        options[key] = Path(options[key])
    for key in ("package_dirs", "joints", "effector_links", "wrist_joints", "limits_names"):
        check_not_one_name(key, options.get(key))
        if key in options and options[key] is not None:
            options[key] = tuple(options[key])
    if isinstance(options.get("held"), Mapping):
        options["held"] = tuple(options["held"].items())
    return RobotSpec(Path(urdf_path), **options).load()


def collision_names(tree: etree._ElementTree) -> dict[str, list[str]]:
    """Collision element names per link, as written in the URDF (or ``link`` / ``link_i`` if unnamed)."""
    names: dict[str, list[str]] = {}
    for link in tree.getroot().findall("link"):
        collisions = link.findall("collision")
        link_name = link.get("name", "")
        names[link_name] = [
            c.get("name") or (link_name if len(collisions) == 1 else f"{link_name}_{i}")
            for i, c in enumerate(collisions)
        ]
    return names
