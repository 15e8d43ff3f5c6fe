"""A robot's own pairs split into near and far, once per robot and margin's rung.

The self-collision test (:class:`~cpr_kin.collision.self_screen.ScreenedSelfTest`) asks coal only
about the pairs whose cheap bounds (:class:`~cpr_kin.bounds.self_bounds.SelfPairBounds`) leave
them in doubt. Which pairs are mostly within a margin is a property of the robot: :class:`SelfScreen`
finds them, and :func:`robot_self_screen` builds it once per robot, set of pairs and
margin's rung (:func:`screen_threshold`; a collision world is built per plan, and the split
costs milliseconds on a robot of a few hundred pairs: ``docs/benchmarks.md``). The near pairs'
grids (:class:`~cpr_kin.collision.near_cells.NearCells`) go with the split, and learn across plans.
"""

from __future__ import annotations

import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import sampled_configurations
from cpr_kin.bounds.reach import GeometryReach
from cpr_kin.bounds.self_bounds import SelfPairBounds
from cpr_kin.collision.near_cells import NearCells
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.shapes.exact_meshes import ExactMesh

if TYPE_CHECKING:
    from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
Pairs = tuple[tuple[int, int], ...]

PROBES = 256
"""Random configurations on which :class:`SelfScreen` finds the pairs that are always near."""
NEAR_SHARE = 0.3
"""Share of those in which a pair's bound is uncertain that makes it a near pair."""
SCREEN_THRESHOLDS_M = (0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
"""The distances [m] the probes may ask the bounds about (:func:`screen_threshold`): a few per
robot, each screen built once."""
TYPICAL_MARGIN_M = 0.01
"""The self margin [m] a :class:`~cpr_kin.collision.self_screen.ScreenedSelfTest` given no screen
splits its pairs for (the planner's default self margin)."""


def screen_threshold(margin_m: float) -> float:
    """The distance [m] a screen's probes ask about for a test of the self margin ``margin_m`` [m].

    Twice the margin (a check asks it plus its step), rounded up to :data:`SCREEN_THRESHOLDS_M`
    (the largest beyond them): a pair uncertain at a far larger distance than the test's is
    mostly certain at the test's, and belongs with the far pairs.
    """
    wanted = 2.0 * margin_m
    return next((t for t in SCREEN_THRESHOLDS_M if t >= wanted), SCREEN_THRESHOLDS_M[-1])


@dataclass(frozen=True)
class SelfScreen:
    """A robot's own pairs split into near and far, with their bounds.

    Some pairs of a serial arm are always close (a link and the one two joints down its
    chain, a few centimetres apart by design): bounding them first would only delay coal.
    The pairs are split on :data:`PROBES` seeded random configurations within the joint
    ranges: those whose bound is within the screen's distance in more than
    :data:`NEAR_SHARE` of them and that have a grid over the joints between their geometries
    (:func:`~cpr_kin.bounds.pair_cells.has_grid`) are *near*, the others *far*
    (``docs/tuning.md``, Kernels). A pair mostly within the distance but without a grid (a
    humanoid's torso and elbow, four joints apart) is far: were it near, every configuration
    would go to coal for every near pair, the gridded ones too.

    Attributes:
        all_bounds: the bounds of every pair, in order.
        far_bounds: the bounds of the far pairs, in order.
        near: ``(P,)`` which pairs are near.
        near_cells: what the near pairs' grids over their joints are known to clear
            (:class:`~cpr_kin.collision.near_cells.NearCells`; it learns as it is asked).
    """

    all_bounds: SelfPairBounds
    far_bounds: SelfPairBounds
    near: BoolArray
    near_cells: NearCells

    @classmethod
    def build(
        cls,
        model: Any,
        geometry_model: Any,
        pairs: Sequence[tuple[int, int]],
        threshold_m: float,
        reach: Sequence[GeometryReach] | None = None,
        exact_meshes: Mapping[int, ExactMesh] | None = None,
        kept: bool = False,
    ) -> SelfScreen:
        """The split of ``pairs`` (geometry indices of ``geometry_model``) on ``model``'s ranges.

        ``threshold_m``: the distance [m] the probes ask the bounds about (:func:`screen_threshold`).
        ``reach``: each geometry's bounds (:func:`cpr_kin.bounds.reach.geometry_reach`); default:
        within ``model``'s limits. ``exact_meshes``: the robot's exact link meshes, for the near
        cells' tests on the meshes (:class:`~cpr_kin.collision.near_cells.NearCells`); default: none.
        ``kept``: the near cells' memory is kept on disk between processes
        (:mod:`cpr_kin.collision.learned_cells`).
        """
        probes = sampled_configurations(model, PROBES, np.random.default_rng(0))
        all_bounds = SelfPairBounds(model, geometry_model, pairs)
        uncertain = all_bounds(probes) <= threshold_m  # the capsules': a squat link's box, which
        # may clear a pair the capsules leave in doubt, is asked after the near pairs' cells
        # (a near pair that the boxes made far went to coal more often, ``docs/tuning.md``)
        mostly = uncertain.mean(axis=0) > NEAR_SHARE
        candidates = [p for p, m in zip(pairs, mostly, strict=True) if m]
        cells = NearCells(model, geometry_model, candidates, reach, exact_meshes, kept)
        gridded = {tuple(p) for p in cells.pairs}  # a pair without a grid is bounded first, as a far one
        near = np.array([tuple(p) in gridded for p in pairs], dtype=bool)
        near.setflags(write=False)
        far = SelfPairBounds(model, geometry_model, [p for p, n in zip(pairs, near, strict=True) if not n])
        return cls(all_bounds, far, near, cells)


_SCREENS: weakref.WeakKeyDictionary[Robot, dict[tuple[Pairs, float], SelfScreen]] = (
    weakref.WeakKeyDictionary()
)


def robot_self_screen(robot: Robot, pairs: Pairs, margin_m: float) -> SelfScreen:
    """:meth:`SelfScreen.build` of ``robot``'s ``pairs`` for the self margin ``margin_m`` [m], built once.

    One per robot, pairs and :func:`screen_threshold`. A :class:`~cpr_kin.Robot` does not
    change; its screens go with it, and what their near cells learn is kept on disk for the
    robot's next process (:mod:`cpr_kin.collision.learned_cells`).
    """
    screens = _SCREENS.setdefault(robot, {})
    key = (pairs, screen_threshold(margin_m))
    if key not in screens:
        model, reach, meshes = robot.model, robot_reach(robot), robot.exact_meshes
        screens[key] = SelfScreen.build(model, robot.collision_model, pairs, key[1], reach, meshes, kept=True)
    return screens[key]
