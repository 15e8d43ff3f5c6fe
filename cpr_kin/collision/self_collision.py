"""A robot against itself: which pairs of its links are checked, and their distances by coal.

The pairs checked are those of collision geometries on links that are not adjacent (two
links carried by the same joint, or by a joint and its parent joint, touch by design),
minus the link pairs an SRDF's ``<disable_collisions>`` lists (MoveIt's: adjacent, always
in contact, or never able to meet) and minus the pairs a scene allows. A robot with no such
pair (the CPR: its SRDF disables all) costs nothing.

The self-clearance required is its own, ``self_margin_m`` (a safety margin against
obstacles is not one a robot can keep from itself: its links pass centimetres apart).
Between two configurations a pair's distance changes only by the joints that carry one of
its links and not the other (:attr:`SelfCollision.pair_radii`), which the certified check of
a curve counts (:mod:`cpr_kin.certified.self_curve`).
"""

from __future__ import annotations

import copy
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from lxml import etree
from numpy.typing import ArrayLike, NDArray

from cpr_kin.bounds.reach import GeometryReach, relative_radii
from cpr_kin.collision.self_screen import ScreenedSelfTest
from cpr_kin.collision.self_split import SelfScreen
from cpr_kin.common.errors import CprKinError, UrdfError
from cpr_kin.common.names import cut
from cpr_kin.common.user_files import read_bytes
from cpr_kin.shapes.exact_meshes import ExactMesh
from cpr_kin.shapes.exact_pairs import ExactPairs

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
LinkPair = frozenset[str]

MAX_SRDF_BYTES = 10_000_000
"""Largest SRDF file [bytes]."""


def find_srdf(urdf_path: Path, robot_name: str | None = None) -> Path | None:
    """The SRDF of a URDF by the default rule (:attr:`cpr_kin.RobotSpec.srdf`), or ``None``.

    Looked for, in order: ``<urdf stem>.srdf`` beside the URDF, then in a ``srdf`` folder
    beside the URDF's folder; then the same with the URDF's robot name (``<robot name=...>``,
    MoveIt's rule: ``ur5_robot.urdf`` names robot ``ur5``, whose SRDF is ``srdf/ur5.srdf``).
    """
    stems = [urdf_path.stem] + ([robot_name] if robot_name and robot_name != urdf_path.stem else [])
    for stem in stems:
        for candidate in (
            urdf_path.parent / f"{stem}.srdf",
            urdf_path.parent.parent / "srdf" / f"{stem}.srdf",
        ):
            if candidate.is_file():
                return candidate
    return None


@dataclass(frozen=True)
class SrdfPairs:
    """The ``<disable_collisions>`` of an SRDF.

    Attributes:
        disabled: the link pairs it disables, both links known to the URDF.
        unknown_links: links it names that the URDF lacks; their entries are skipped, as
            MoveIt skips them (with a warning), and the loaded robot reports them.
    """

    disabled: frozenset[LinkPair]
    unknown_links: tuple[str, ...] = ()


def parse_srdf(path: Path) -> etree._Element:
    """The root element of the SRDF file ``path``, parsed as strict XML (no entities, no network).

    Raises:
        UrdfError: the file is missing, too large or not well-formed XML.
    """
    parser = etree.XMLParser(recover=False, resolve_entities=False, no_network=True)
    try:
        root = etree.fromstring(read_bytes(path, MAX_SRDF_BYTES, "SRDF file"), parser)
    except etree.XMLSyntaxError as exc:
        raise UrdfError(f"SRDF file '{path}' is not well-formed XML: {str(exc)[:120]}") from None
    except CprKinError as exc:
        raise UrdfError(str(exc)) from None
    if root.tag != "robot":
        raise UrdfError(
            f"SRDF file '{path}' has root element <{cut(str(root.tag), 40)}>; an SRDF's is <robot>"
        )
    if root.find("link") is not None or root.find("joint") is not None:
        raise UrdfError(
            f"SRDF file '{path}' holds <link> or <joint> elements: it is a URDF; give the robot's "
            "SRDF (groups, disable_collisions), which MoveIt's setup assistant writes"
        )
    return root


def read_srdf(path: Path, links: Iterable[str]) -> SrdfPairs:
    """The link pairs an SRDF disables (:class:`SrdfPairs`), as MoveIt reads them.

    Those ``<disable_collisions link1 link2>`` lists, and every pair of a link that
    ``<disable_default_collisions link>`` names, but those ``<enable_collisions link1 link2>``
    lists (srdfdom's default entries and their exceptions).

    Raises:
        UrdfError: the file is unreadable or not XML.
    """
    root = parse_srdf(path)
    known = set(links)
    unknown: set[str] = set()

    def listed(tag: str) -> set[LinkPair]:
        found = set()
        for element in root.iter(tag):
            pair = (element.get("link1", ""), element.get("link2", ""))
            missing = {link for link in pair if link not in known}
            unknown.update(missing)
            if not missing:
                found.add(frozenset(pair))
        return found

    pairs, enabled = listed("disable_collisions"), listed("enable_collisions")
    for element in root.iter("disable_default_collisions"):
        link = element.get("link", "")
        if link not in known:
            unknown.add(link)
            continue
        pairs |= {frozenset((link, other)) for other in known if other != link} - enabled
    return SrdfPairs(frozenset(pairs), tuple(sorted(unknown)))


def adjacent(model: Any, joint_a: int, joint_b: int) -> bool:
    """Links on joints ``joint_a`` and ``joint_b`` are adjacent: the same joint, or one the other's parent."""
    return bool(joint_a == joint_b or model.parents[joint_a] == joint_b or model.parents[joint_b] == joint_a)


def self_pairs(
    model: Any, collision_model: Any, disabled: frozenset[LinkPair]
) -> tuple[tuple[int, int], ...]:
    """Geometry index pairs ``(a, b)``, ``a < b``, on non-adjacent links not ``disabled``.

    Links are the frames the geometries hang on; two links are adjacent when the same joint
    carries both, or the joint of one is the parent of the other's.
    """
    objects = collision_model.geometryObjects
    found = []
    for a in range(len(objects)):
        for b in range(a + 1, len(objects)):
            if adjacent(model, objects[a].parentJoint, objects[b].parentJoint):
                continue
            link_a = model.frames[objects[a].parentFrame].name
            link_b = model.frames[objects[b].parentFrame].name
            if frozenset((link_a, link_b)) in disabled or link_a == link_b:
                continue
            found.append((a, b))
    return tuple(found)


class SelfCollision:
    """Distances between a robot's own geometry pairs, for one configuration or a batch.

    Args:
        model: the robot's Pinocchio model.
        collision_model: its collision geometry model (copied, never modified).
        pairs: geometry index pairs to check (:func:`self_pairs`).
        names: the geometries' names, by index.
        num_threads: threads of :meth:`violated`'s batches.
        reach: each geometry's bounds (:func:`cpr_kin.bounds.reach.geometry_reach`, within the
            robot's joint ranges); by default from the model's position limits.
        allowance_m: ``(P,)`` added to each pair's coal distance [m] wherever a distance,
            bound or margin is asked (:attr:`allowance_m`); default none.
        screen: the pairs' near/far split and bounds (:class:`~cpr_kin.collision.self_split.SelfScreen`);
            by default built on the first query.
        exact_meshes: the robot's exact link meshes by geometry index
            (:attr:`cpr_kin.Robot.exact_meshes`): where a hull comes within a margin, the mesh
            decides (:mod:`cpr_kin.shapes.exact_pairs`). Default: none.
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        pairs: tuple[tuple[int, int], ...],
        names: list[str],
        num_threads: int = 1,
        reach: Sequence[GeometryReach] | None = None,
        allowance_m: FloatArray | None = None,
        screen: SelfScreen | None = None,
        exact_meshes: Mapping[int, ExactMesh] | None = None,
    ) -> None:
        self.model = model
        self.geometry_model = collision_model.copy()
        for a, b in pairs:
            self.geometry_model.addCollisionPair(pin.CollisionPair(a, b))
        self.pair_radii = relative_radii(model, collision_model, pairs, reach)
        """``(P, nj)`` per pair, how fast its distance may change per joint speed [m/rad, m/m]
        (:func:`cpr_kin.bounds.reach.relative_radii`)."""
        self.allowance_m = (
            np.zeros(len(pairs)) if allowance_m is None else np.asarray(allowance_m, dtype=float)
        )
        """``(P,)`` what each pair's distance counts beyond coal's [m]: a world's self margin for a
        pair it holds to contact only (:mod:`cpr_kin.bounds.close_pairs`), else 0. Every distance,
        bound and margin of this class is of coal's distance plus it."""
        if self.allowance_m.shape != (len(pairs),) or not np.all(self.allowance_m >= 0.0):
            raise CprKinError(f"allowance_m must be {len(pairs)} distances >= 0 [m], one per pair")
        self._pairs = pairs
        self._names = names
        self.num_threads = num_threads
        self._screen = screen
        self._exact = ExactPairs(self.geometry_model, exact_meshes or {})
        self._test: ScreenedSelfTest | None = None  # built on the first query

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        """``(geometry, geometry)`` of every pair, in query order."""
        return tuple((self._names[a], self._names[b]) for a, b in self._pairs)

    def __bool__(self) -> bool:
        return bool(self._pairs)

    def distances(self, q: ArrayLike) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair, ``(N,)`` each, at configurations ``q`` ``(N, nq)``.

        A pair's distance is coal's plus its :attr:`allowance_m`; ``inf`` and ``-1`` when there
        is no pair.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs:
            return np.full(len(batch), np.inf), np.full(len(batch), -1, dtype=np.int64)
        return self._screened().distances(batch)

    def pair_distances(self, q: FloatArray, pair: int, exact_below_m: float = np.inf) -> FloatArray:
        """``(N,)`` coal's distance [m] of pair ``pair`` (index in :attr:`pairs`) at ``q`` ``(N, nq)``.

        Measured on the exact meshes (:mod:`cpr_kin.shapes.exact_pairs`) where the hulls' distance is
        below ``exact_below_m`` [m]; above it, the hulls' (a lower bound).
        """
        return self._screened().pair_distances(np.atleast_2d(np.asarray(q, dtype=float)), pair, exact_below_m)

    def bounds(self, q: FloatArray) -> FloatArray:
        """``(N, P)`` lower bounds [m] of every pair's distance at ``q`` ``(N, nq)`` (:meth:`pair_bounds`)."""
        return self._screened().bounds(np.atleast_2d(np.asarray(q, dtype=float)))

    def pair_bounds(self, q: FloatArray, pair: int) -> FloatArray:
        """``(N,)`` lower bounds [m] of pair ``pair``'s distance at configurations ``q`` ``(N, nq)``, cheaply.

        Its capsules' distance (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`), at most coal's
        plus coal's error (:func:`~cpr_kin.collision.decisive.coal_error_m`).
        """
        return self._screened().pair_bounds(np.atleast_2d(np.asarray(q, dtype=float)), pair)

    def violated(self, q: ArrayLike, margin_m: float, ordered: bool = False) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``q``.

        coal's collision test with ``margin_m`` as its security margin, which stops at the first
        pair closer than that, in parallel over :attr:`num_threads` threads, screened by the
        pairs' cheap bounds (:class:`~cpr_kin.collision.self_screen.ScreenedSelfTest`): a fraction of
        :meth:`distances`' cost, with the same answer. With ``ordered``, the answer is exact up
        to the first violated configuration, and those after it are reported violated: what an
        edge check needs, without the exact meshes' tests of the configurations past it.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs or not len(batch):
            return np.zeros(len(batch), dtype=bool)
        return self._screened().violated(batch, margin_m, ordered)

    def on_hulls(self) -> SelfCollision:
        """The pairs with the hulls deciding alone (:meth:`cpr_kin.CollisionWorld.on_hulls`)."""
        hulls = copy.copy(self)
        hulls._exact = ExactPairs(self.geometry_model, {})
        if self._pairs:
            hulls._test = self._screened().on_hulls()
        return hulls

    def _screened(self) -> ScreenedSelfTest:
        """The screened coal queries of the pairs, built on first use."""
        if self._test is None:
            self._test = ScreenedSelfTest(
                self.model,
                self.geometry_model,
                self._pairs,
                self.num_threads,
                self.allowance_m,
                self._screen,
                self._exact,
            )
        return self._test
