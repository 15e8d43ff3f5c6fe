"""The robot-obstacle margin tests a compiled GJK decides for a batch, before coal is asked.

:class:`~cpr_kin.collision.obstacle_tests.ObstacleTests` asks coal, pair by pair, whether the
pairs its bounds leave uncertain come within the margin; each question costs a Python call,
and each configuration a placement of every geometry. Where a pair's two shapes are convex
(coal's convex hulls, boxes, spheres, capsules, cylinders) and the robot's joints have one
degree of freedom each, :class:`HullTests` answers the whole batch in one compiled call: the
joints placed by :func:`~cpr_kin.bounds.batch_kinematics.place_joints`, each pair tested by
:func:`~cpr_kin.shapes.convex_gjk.margin_state`. It answers only where GJK's bounds clear the
margin by :data:`BAND_ERRORS` times coal's error, so that coal would answer the same; the
rest (a distance near the margin, a shape of another kind) are left to coal.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, KinematicChain, place_joints
from cpr_kin.collision.decisive import coal_error_m
from cpr_kin.common.compiled import njit
from cpr_kin.common.errors import CprKinError
from cpr_kin.shapes.coal_queries import collide_margin_m
from cpr_kin.shapes.convex_gjk import CLEAR, HIT, UNSUPPORTED, UNSURE, margin_state
from cpr_kin.shapes.gjk_shapes import GeometryShapes

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

HULL_HIT = 3
"""A test's state beside :mod:`~cpr_kin.shapes.convex_gjk`'s: within the margin on a hull whose
exact mesh decides."""
NONE_LEFT = np.empty(0, dtype=np.int64)
NONE_LEFT.setflags(write=False)
"""No test left (what most calls return)."""
BAND_ERRORS = 4.0
"""How many times coal's error (:func:`~cpr_kin.collision.decisive.coal_error_m`) a distance must
clear the margin by to be decided here."""


class HullTests:
    """The margin tests of a geometry model's pairs, decided in one compiled call where GJK can.

    Args:
        model: the robot's Pinocchio model (joints of one degree of freedom each).
        geometry_model: the world's geometry model.

    Raises:
        CprKinError: a joint has more than one degree of freedom (coal decides every pair).
    """

    def __init__(self, model: Any, geometry_model: Any) -> None:
        self._chain = KinematicChain.from_model(model).arrays
        self.shapes = GeometryShapes.of(geometry_model)
        self._pairs = np.array(
            [(pair.first, pair.second) for pair in geometry_model.collisionPairs], dtype=np.int64
        ).reshape(-1, 2)
        shapes = self.shapes
        self._shapes = (shapes.kinds, shapes.half, shapes.first, shapes.vertices, shapes.radii)
        self._fixed = (shapes.joints, shapes.rotations, shapes.translations)
        self._guesses = np.zeros((len(self._pairs), 3))
        self._margins: dict[float, tuple[float, float]] = {}
        self._left = np.empty((0, 3), dtype=np.int64)  # the tests left, (row, pair, state); grown when needed

    @classmethod
    def of(cls, model: Any, geometry_model: Any) -> HullTests | None:
        """The tests of ``geometry_model``, or ``None`` where its robot's joints are not all simple."""
        try:
            return cls(model, geometry_model)
        except CprKinError:
            return None

    def violated(
        self,
        batch: FloatArray,
        uncertain: BoolArray,
        pairs: IntArray,
        margin_m: float,
        refined: BoolArray,
        ordered: bool,
    ) -> Verdicts:
        """Which configurations GJK finds within ``margin_m`` [m], and the tests it leaves.

        Args:
            batch: ``(N, nq)`` configurations.
            uncertain: ``(N, P)`` the pairs to test at each.
            pairs: ``(P,)`` those pairs' indices in the geometry model's collision pairs.
            margin_m: the security margin [m] (coal's floor applies, as to coal's own test).
            refined: ``(C,)`` per collision pair of the geometry model, whether a hit on its
                hull is left to its exact mesh (``HULL_HIT``).
            ordered: no test after the first configuration found within the margin; those
                after it are reported violated.
        """
        if margin_m not in self._margins:
            margin = float(collide_margin_m(margin_m))
            self._margins[margin_m] = (margin, BAND_ERRORS * coal_error_m(margin))
        margin, band = self._margins[margin_m]
        violated = np.zeros(len(batch), dtype=bool)
        if len(self._left) < uncertain.size:  # at most one entry a test: grown where it may not hold them
            needed = int(np.count_nonzero(uncertain))
            if len(self._left) < needed:
                self._left = np.empty((needed, 3), dtype=np.int64)
        left = self._left
        count = _decide(
            (np.ascontiguousarray(batch, dtype=float), np.ascontiguousarray(uncertain), pairs),
            self._pairs,
            refined,
            self._chain,
            self._shapes,
            self._fixed,
            self._guesses,
            (margin, band),
            ordered,
            violated,
            left,
        )
        if not count:
            return Verdicts(violated, NONE_LEFT, NONE_LEFT, NONE_LEFT)
        rows, pairs_left, states = left[:count].T.copy()
        return Verdicts(violated, rows, pairs_left, states)


class Verdicts(NamedTuple):
    """:meth:`HullTests.violated`'s answer.

    Attributes:
        violated: ``(N,)`` the configurations found within the margin (with ``ordered``, and
            every one after the first).
        rows: ``(L,)`` the configurations of the tests left to coal, ascending.
        pairs: ``(L,)`` their pairs.
        states: ``(L,)`` ``UNSURE`` (coal decides) or ``HULL_HIT`` (the pair's exact mesh decides).
    """

    violated: BoolArray
    rows: IntArray
    pairs: IntArray
    states: IntArray


@njit
def _decide(
    tests: tuple[FloatArray, BoolArray, IntArray],
    pair_geometries: IntArray,
    refined: BoolArray,
    chain: ChainArrays,
    shapes: tuple[IntArray, FloatArray, IntArray, FloatArray, FloatArray],
    fixed: tuple[IntArray, FloatArray, FloatArray],
    guesses: FloatArray,
    margins: tuple[float, float],
    ordered: bool,
    violated: BoolArray,
    left: IntArray,
) -> int:
    """:meth:`HullTests.violated` into ``violated`` and ``left`` (row, pair, state); how many are left.

    A row's pairs without an exact mesh first (their hulls decide alone), then the others.
    """
    batch, uncertain, pairs = tests
    kinds, half, first, vertices, radii = shapes
    cores = (kinds, half, first, vertices)
    joints, in_joint_rotation, in_joint_translation = fixed
    margin_m, band_m = margins
    count, joint_count = len(kinds), len(chain[0])
    rotation, translation = np.empty((count, 3, 3)), np.empty((count, 3))
    joint_rotation, joint_translation = np.empty((joint_count, 3, 3)), np.empty((joint_count, 3))
    local, simplex, weights = np.empty((4, 3)), np.empty((4, 3)), np.empty(4)
    placed_row = np.full(count, -1, dtype=np.int64)
    joints_row, n_left = -1, 0
    for row in range(len(batch)):
        for meshed in (False, True):
            for c in range(len(pairs)):
                pair = pairs[c]
                if not uncertain[row, c] or refined[pair] != meshed or violated[row]:
                    continue
                g1, g2 = pair_geometries[pair, 0], pair_geometries[pair, 1]
                state: int | np.int64 = np.int64(UNSURE)  # typed as margin_state returns it, not as a literal
                if kinds[g1] != UNSUPPORTED and kinds[g2] != UNSUPPORTED:
                    for g in (g1, g2):  # each geometry placed once per configuration, when a test needs it
                        if placed_row[g] == row:
                            continue
                        placed_row[g] = row
                        j = joints[g]
                        if j >= 0 and joints_row != row:
                            place_joints(batch[row], chain, joint_rotation, joint_translation, local)
                            joints_row = row
                        _place(
                            g,
                            j,
                            joint_rotation,
                            joint_translation,
                            in_joint_rotation,
                            in_joint_translation,
                            rotation,
                            translation,
                        )
                    reach = margin_m + radii[g1] + radii[g2]
                    state = margin_state(
                        g1,
                        g2,
                        cores,
                        rotation,
                        translation,
                        reach - band_m,
                        reach + band_m,
                        guesses[pair],
                        simplex,
                        weights,
                    )
                if state == HIT and not meshed:
                    violated[row] = True
                elif state != CLEAR:
                    left[n_left, 0], left[n_left, 1] = row, pair
                    left[n_left, 2] = HULL_HIT if state == HIT else UNSURE
                    n_left += 1
        if ordered and violated[row]:
            violated[row:] = True
            break
    return n_left


@njit
def _place(
    g: int,
    j: int,
    joint_rotation: FloatArray,
    joint_translation: FloatArray,
    in_joint_rotation: FloatArray,
    in_joint_translation: FloatArray,
    rotation: FloatArray,
    translation: FloatArray,
) -> None:
    """Geometry ``g``'s placement in the world: its joint ``j``'s (-1: the world's) times its own in it."""
    for r in range(3):
        if j < 0:
            translation[g, r] = in_joint_translation[g, r]
            for c in range(3):
                rotation[g, r, c] = in_joint_rotation[g, r, c]
            continue
        translation[g, r] = joint_translation[j, r]
        for c in range(3):
            translation[g, r] += joint_rotation[j, r, c] * in_joint_translation[g, c]
            rotation[g, r, c] = (
                joint_rotation[j, r, 0] * in_joint_rotation[g, 0, c]
                + joint_rotation[j, r, 1] * in_joint_rotation[g, 1, c]
                + joint_rotation[j, r, 2] * in_joint_rotation[g, 2, c]
            )
