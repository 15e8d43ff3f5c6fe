"""coal's yes/no margin test of the robot-obstacle pairs their bounds leave uncertain.

Where a configuration's pair bounds (:meth:`cpr_kin.bounds.pair_bounds.PairBounds.pairs_below`)
leave some pair uncertain, coal decides: the configuration's geometries are placed once, and
coal tests those pairs alone, one after another, up to the first within the margin. Every
other pair is certainly farther. (Before, every pair of an obstacle with an uncertain pair
went to coal in a Pinocchio ``GeometryPool``: five to eight times the pairs the bounds leave,
on MotionBenchMaker's Panda and UR5; docs/tuning.md, Kernels.) Where a pair's robot link has
an exact mesh that decides (:mod:`cpr_kin.shapes.exact_pairs`), a hull test that flags it is
decided again on the mesh; a configuration's pairs without a mesh are tested first, since
their hulls decide alone and one found within the margin spares the meshes' tests. Where the
robot's joints and the pairs' shapes allow, :mod:`cpr_kin.collision.hull_tests` decides the
batch first, in one compiled call, giving coal's answers: coal is then asked only for the
tests it leaves (a distance at the margin, a shape it does not take).
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.collision.coal_pools import set_margins
from cpr_kin.collision.hull_tests import HullTests, Verdicts
from cpr_kin.shapes.convex_gjk import UNSURE
from cpr_kin.shapes.exact_pairs import ExactPairs

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

MAX_MARGINS = 8
"""Margins whose geometry data is kept; more are dropped and set again (a plan asks a few)."""


class ObstacleTests:
    """coal's margin test of chosen robot-obstacle pairs, configuration by configuration.

    Args:
        model: the robot's Pinocchio model.
        geometry_model: the world's geometry model (robot and obstacles, every pair added).
        exact: the pairs on the robot's exact meshes (default: none decides).
    """

    def __init__(self, model: Any, geometry_model: Any, exact: ExactPairs | None = None) -> None:
        self.model, self.geometry_model = model, geometry_model
        self._exact = exact if exact else None
        self._data = model.createData()
        self._exact_data: Any = None
        self._at_margin: dict[float, Any] = {}
        self._hulls = HullTests.of(model, geometry_model)
        # which hulls' hits a mesh decides, writable (the compiled tests take one array type)
        self._meshed = np.zeros(len(geometry_model.collisionPairs), dtype=bool)
        if self._exact is not None:
            self._meshed[:] = self._exact.refined

    def on_hulls(self) -> ObstacleTests:
        """The tests with the hulls deciding alone (:meth:`cpr_kin.CollisionWorld.on_hulls`)."""
        hulls = copy.copy(self)
        hulls._exact = None
        hulls._meshed = np.zeros_like(self._meshed)
        return hulls

    def violated(
        self,
        batch: FloatArray,
        uncertain: BoolArray,
        pairs: IntArray,
        margin_m: float,
        ordered: bool = False,
    ) -> BoolArray:
        """``(N,)`` whether some pair is closer than ``margin_m`` [m] at configurations ``batch``.

        Args:
            batch: ``(N, nq)`` configurations.
            uncertain: ``(N, P)`` the pairs coal must test at each (the others are certainly
                farther than the margin).
            pairs: ``(P,)`` those pairs' indices in the geometry model's collision pairs.
            margin_m: the security margin [m].
            ordered: decide the configurations in order up to the first violated one; those
                after it are reported violated without a test.
        """
        if not uncertain.any():  # every pair certainly farther: most of a sampling planner's queries
            return np.zeros(len(batch), dtype=bool)
        if self._hulls is not None:
            verdicts = self._hulls.violated(batch, uncertain, pairs, margin_m, self._meshed, ordered)
            if len(verdicts.rows):
                self._ask_coal(batch, verdicts, margin_m, ordered)
            return verdicts.violated
        violated = np.zeros(len(batch), dtype=bool)
        # row by row, in order; NumPy's nonzero of a 2-d array costs 5x this on a plan's batches
        flat = uncertain.ravel().nonzero()[0]
        rows, columns = np.divmod(flat, uncertain.shape[1])
        if self._exact is not None:  # a row's pairs without a mesh first: their hulls decide alone
            meshed = self._exact.refined[pairs[columns]]
            if meshed.any():
                order = np.lexsort((meshed, rows))
                rows, columns = rows[order], columns[order]
        unsure = np.full(len(rows), UNSURE, dtype=np.int64)
        self._ask_coal(batch, Verdicts(violated, rows, pairs[columns], unsure), margin_m, ordered)
        return violated

    def _ask_coal(self, batch: FloatArray, left: Verdicts, margin_m: float, ordered: bool) -> None:
        """Decide the tests ``left`` holds (their rows ascending) by coal, into ``left.violated``.

        A test's ``HULL_HIT`` needs its mesh only; with ``ordered``, a configuration found
        violated marks every later one so.
        """
        violated = left.violated
        model, data, geometry_model = self.model, self._data, self.geometry_model
        geometry_data = self._geometry_data(margin_m)
        placed = -1
        for row, pair, state in zip(
            left.rows.tolist(), left.pairs.tolist(), left.states.tolist(), strict=True
        ):
            if violated[row]:  # this row was found within the margin (or lies past an ordered hit)
                continue
            if state == UNSURE:
                if row != placed:
                    pin.updateGeometryPlacements(model, data, geometry_model, geometry_data, batch[row])
                    placed = row
                if not pin.computeCollision(geometry_model, geometry_data, pair):
                    continue
            if not self._clear_on_mesh(batch[row], pair, margin_m):
                violated[row] = True
                if ordered:
                    violated[row:] = True
                    return

    def _clear_on_mesh(self, q: FloatArray, pair: int, margin_m: float) -> bool:
        """Whether ``pair``, flagged on its hull at ``q``, keeps ``margin_m`` [m] on its exact mesh."""
        exact = self._exact
        if exact is None or not exact.refined[pair]:
            return False
        if self._exact_data is None:
            self._exact_data = self.geometry_model.createData()
        data = (self.model, self._data, self.geometry_model, self._exact_data)
        return not exact.violated(*data, q[None], [pair], margin_m)[0]

    def _geometry_data(self, margin_m: float) -> Any:
        """A geometry data whose collision tests have the security margin ``margin_m`` [m]."""
        if margin_m not in self._at_margin:
            if len(self._at_margin) >= MAX_MARGINS:
                self._at_margin.clear()
            geometry_data = self.geometry_model.createData()
            set_margins(geometry_data, self.geometry_model, margin_m)
            self._at_margin[margin_m] = geometry_data
        return self._at_margin[margin_m]
