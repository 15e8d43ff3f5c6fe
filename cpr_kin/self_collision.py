"""A robot against itself: which pairs of its links are checked, and their distances by coal.

The pairs checked are those of collision geometries on links that are not adjacent (two
links carried by the same joint, or by a joint and its parent joint, touch by design),
minus the link pairs an SRDF's ``<disable_collisions>`` lists (MoveIt's: adjacent, always
in contact, or never able to meet) and minus the pairs a scene allows. A robot with no such
pair (the CPR: its SRDF disables all) costs nothing.

The self-clearance required is its own, ``self_margin_m`` (a safety margin against
obstacles is not one a robot can keep from itself: its links pass centimetres apart).
Between two configurations both links of a pair move: their distance changes at most twice
as fast as the fastest robot point (:func:`cpr_kin.motion_radii`), which the certified check
of a curve counts.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
from lxml import etree
from numpy.typing import ArrayLike, NDArray

from cpr_kin.decisive import propagated_bounds, undecided
from cpr_kin.errors import CprKinError, UrdfError
from cpr_kin.interval_motion import IntervalSpeed, interval_motion
from cpr_kin.self_bounds import ScreenedSelfTest
from cpr_kin.user_files import read_bytes

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
LinkPair = frozenset[str]

MAX_SRDF_BYTES = 10_000_000
"""Largest SRDF file [bytes]."""
MAX_SELF_CHECKS = 200_000
"""Most configurations one certified self-collision check of a curve samples."""
COARSE_STRIDE = 8
"""The certified self check computes every this many samples first, the rest where they decide."""


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
        return etree.fromstring(read_bytes(path, MAX_SRDF_BYTES, "SRDF file"), parser)
    except etree.XMLSyntaxError as exc:
        raise UrdfError(f"SRDF file '{path}' is not well-formed XML: {str(exc)[:120]}") from None
    except CprKinError as exc:
        raise UrdfError(str(exc)) from None


def read_srdf(path: Path, links: Iterable[str]) -> SrdfPairs:
    """The link pairs an SRDF's ``<disable_collisions link1 link2>`` lists (:class:`SrdfPairs`).

    Raises:
        UrdfError: the file is unreadable or not XML.
    """
    root = parse_srdf(path)
    known = set(links)
    pairs = set()
    unknown: set[str] = set()
    for element in root.iter("disable_collisions"):
        pair = (element.get("link1", ""), element.get("link2", ""))
        missing = {link for link in pair if link not in known}
        unknown |= missing
        if not missing:
            pairs.add(frozenset(pair))
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
    """

    def __init__(
        self,
        model: Any,
        collision_model: Any,
        pairs: tuple[tuple[int, int], ...],
        names: list[str],
        num_threads: int = 1,
    ) -> None:
        self.model = model
        self.geometry_model = collision_model.copy()
        for a, b in pairs:
            self.geometry_model.addCollisionPair(pin.CollisionPair(a, b))
        self._pairs = pairs
        self._names = names
        self.num_threads = num_threads
        self._test: ScreenedSelfTest | None = None  # built on the first query

    @property
    def pairs(self) -> tuple[tuple[str, str], ...]:
        """``(geometry, geometry)`` of every pair, in query order."""
        return tuple((self._names[a], self._names[b]) for a, b in self._pairs)

    def __bool__(self) -> bool:
        return bool(self._pairs)

    def distances(self, q: ArrayLike) -> tuple[FloatArray, IntArray]:
        """Smallest self distance [m] and its pair, ``(N,)`` each, at configurations ``q`` ``(N, nq)``.

        ``inf`` and ``-1`` when there is no pair.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs:
            return np.full(len(batch), np.inf), np.full(len(batch), -1, dtype=np.int64)
        return self._screened().distances(batch)

    def violated(self, q: ArrayLike, margin_m: float) -> NDArray[np.bool_]:
        """``(N,)`` whether any pair is closer than ``margin_m`` [m] at configurations ``q``.

        coal's collision test with ``margin_m`` as its security margin, which stops at the first
        pair closer than that, in parallel over :attr:`num_threads` threads, screened by the
        pairs' cheap bounds (:class:`~cpr_kin.self_bounds.ScreenedSelfTest`): a fraction of
        :meth:`distances`' cost, with the same answer.
        """
        batch = np.atleast_2d(np.asarray(q, dtype=float))
        if not self._pairs or not len(batch):
            return np.zeros(len(batch), dtype=bool)
        return self._screened().violated(batch, margin_m)

    def _screened(self) -> ScreenedSelfTest:
        """The screened coal queries of the pairs, built on first use."""
        if self._test is None:
            self._test = ScreenedSelfTest(self.model, self.geometry_model, self._pairs, self.num_threads)
        return self._test


@dataclass(frozen=True)
class SelfCheck:
    """Result of :func:`check_self_curve`.

    Attributes:
        accepted: the certified self-clearance is at least the margin everywhere.
        margin_m: the self-clearance required [m].
        checks: configurations sampled (each certified).
        computed: those whose distances coal computed, the others bounded from them.
        certified_min_m: lower bound of the self-clearance over the whole curve [m]
            (``inf`` without pairs).
        worst_time: instant of the smallest sampled self-clearance [s].
        worst_pair: the geometry pair closest then, or ``None``.
    """

    accepted: bool
    margin_m: float
    checks: int
    computed: int
    certified_min_m: float
    worst_time: float
    worst_pair: tuple[str, str] | None


def check_self_curve(
    collision: SelfCollision,
    curve: Callable[[FloatArray], FloatArray],
    interval: tuple[float, float],
    point_speed: float,
    margin_m: float,
    step_m: float,
    interval_speed: IntervalSpeed | None = None,
) -> SelfCheck:
    """Certify that the curve ``q(t)`` over ``interval`` keeps ``margin_m`` between the robot's own pairs.

    ``point_speed`` [m/s] bounds how fast any robot point moves (``motion_radii @ |q'|``);
    two points of a pair approach at most twice as fast, so the curve is sampled every
    ``dt = 2 step_m / (2 point_speed)`` and between samples ``k`` and ``k + 1`` the distance
    is at least ``(c_k + c_{k+1} - 2 point_speed dt) / 2``; with ``interval_speed``
    (:data:`cpr_kin.interval_motion.IntervalSpeed`), the lower of its bound and ``point_speed`` for
    each interval. coal computes only the samples that decide the smallest certified and
    sampled distances (:func:`_decisive_distances`); the result is that of every sample computed.

    Raises:
        CprKinError: more than :data:`~cpr_kin.motion.MAX_CURVE_CHECKS` samples needed.
    """
    t0, t1 = interval
    if not collision:
        return SelfCheck(True, float(margin_m), 0, 0, np.inf, t0, None)
    fastest = 2.0 * point_speed
    count = int(np.ceil((t1 - t0) * fastest / (2.0 * step_m))) + 1 if fastest > 0 else 1
    if count > MAX_SELF_CHECKS:
        raise CprKinError(
            f"the self-collision check needs {count} samples ({t1 - t0:.4g} s of motion, step {step_m:g} m); "
            f"at most {MAX_SELF_CHECKS}: use a larger step"
        )
    times = np.linspace(t0, t1, max(count, 2))
    approach = 2.0 * interval_motion(times, point_speed, interval_speed)  # per interval [m]
    distance, closest, computed = _decisive_distances(collision, curve(times), approach)
    certified = 0.5 * (distance[:-1] + distance[1:] - approach)
    worst = int(np.argmin(distance))
    pair = collision.pairs[int(closest[worst])] if closest[worst] >= 0 else None
    lowest = float(certified.min())
    return SelfCheck(
        bool(lowest >= margin_m), float(margin_m), len(times), computed, lowest, float(times[worst]), pair
    )


def _decisive_distances(
    collision: SelfCollision, q: FloatArray, approach_m: FloatArray
) -> tuple[FloatArray, IntArray, int]:
    """Self distances [m] of the samples ``q`` ``(K, nq)``, exact where they decide the check.

    Every :data:`COARSE_STRIDE`-th sample is computed first; the others are bounded from
    them (distances change by at most ``approach_m`` ``(K - 1,)`` [m] between neighbours),
    and coal computes those whose exact value could still lower the smallest certified or
    sampled value (:func:`cpr_kin.decisive.undecided`) until both are exact. Elsewhere the
    distance is the lower bound and the pair ``-1``.
    """
    count = len(q)
    distance, closest = np.zeros(count), np.full(count, -1, dtype=np.int64)
    known = np.zeros(count, dtype=bool)
    reach = np.concatenate([[0.0], np.cumsum(approach_m)])
    rows = np.unique(np.append(np.arange(0, count, COARSE_STRIDE), count - 1))
    while rows.size:
        distance[rows], closest[rows] = collision.distances(q[rows])
        known[rows] = True
        distance = propagated_bounds(distance, known, reach)
        rows = np.flatnonzero(undecided(distance[:, None], known[:, None], approach_m)[:, 0])
    return distance, closest, int(known.sum())
