"""GJK's margin test: where it decides, coal's distance agrees; its simplex's closest point is the hull's."""

from __future__ import annotations

import itertools
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize

from cpr_kin.shapes.convex_gjk import CLEAR, HIT, UNSURE, margin_state, reduce_simplex
from cpr_kin.shapes.gjk_shapes import GeometryShapes
from cpr_kin.shapes.mesh_geometry import convex_hull

BAND_M = 4e-6
"""The band about the margin where the test may leave the answer to coal [m]."""


def shapes(rng: np.random.Generator) -> dict[str, Any]:
    """One coal shape of each kind the test supports, a convex one and a swept box among them."""
    points = rng.normal(size=(40, 3)) * (0.05, 0.08, 0.12)
    swept = coal.Box(0.1, 0.06, 0.2)
    swept.setSweptSphereRadius(0.01)
    return {
        "convex": convex_hull(points),
        "box": coal.Box(0.2, 0.1, 0.15),
        "sphere": coal.Sphere(0.07),
        "capsule": coal.Capsule(0.04, 0.2),
        "cylinder": coal.Cylinder(0.05, 0.18),
        "swept box": swept,
    }


def placed_pair(first: Any, second: Any, rng: np.random.Generator) -> tuple[GeometryShapes, list[pin.SE3]]:
    """Two shapes fixed to the world at random placements, as the compiled test reads them."""
    model = pin.GeometryModel()
    placements = []
    for k, shape in enumerate((first, second)):
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.25, 0.25, 3))
        model.addGeometryObject(pin.GeometryObject(f"g{k}", 0, 0, placement, shape))
        placements.append(placement)
    return GeometryShapes.of(model), placements


def state_of(table: GeometryShapes, margin_m: float, guess: np.ndarray | None = None) -> int:
    reach = margin_m + table.radii[0] + table.radii[1]
    return int(
        margin_state(
            0,
            1,
            table.cores,
            table.rotations,
            table.translations,
            reach - BAND_M,
            reach + BAND_M,
            np.zeros(3) if guess is None else guess,
            np.empty((4, 3)),
            np.empty(4),
        )
    )


@pytest.mark.parametrize("kinds", list(itertools.combinations_with_replacement(range(6), 2)))
def test_a_decided_test_is_coal_s_distance_against_the_margin(kinds: tuple[int, int]) -> None:
    rng = np.random.default_rng(sum(kinds) * 7 + kinds[0])
    named = list(shapes(rng).values())
    first, second = named[kinds[0]], named[kinds[1]]
    answers = {CLEAR: 0, HIT: 0, UNSURE: 0}
    for _ in range(150):
        table, placements = placed_pair(first, second, rng)
        request, result = coal.DistanceRequest(), coal.DistanceResult()
        distance = coal.distance(
            first, coal.Transform3s(placements[0]), second, coal.Transform3s(placements[1]), request, result
        )
        for margin_m in (0.01, 0.08):
            state = state_of(table, margin_m)
            answers[state] += 1
            if state == CLEAR:
                assert distance > margin_m - 1e-6
            elif state == HIT:
                assert distance < margin_m + 1e-6
            else:  # only near the margin, or where the cores overlap at no margin
                assert abs(distance - margin_m) < 1e-4
            guess = rng.normal(size=3)  # the answer whatever the start
            assert state_of(table, margin_m, guess) in (state, UNSURE)
    assert answers[CLEAR] > 50 and answers[HIT] > 20  # both occur, and nearly every test decides
    assert answers[UNSURE] <= 3


def closest_of_hull(points: np.ndarray) -> float:
    """The distance from the origin to the hull of ``points`` (a quadratic programme, SLSQP)."""
    k = len(points)
    found = minimize(
        lambda w: float(np.sum((w @ points) ** 2)),
        np.full(k, 1.0 / k),
        jac=lambda w: 2.0 * points @ (w @ points),
        bounds=[(0.0, 1.0)] * k,
        constraints=[{"type": "eq", "fun": lambda w: np.sum(w) - 1.0}],
        method="SLSQP",
        options={"ftol": 1e-15, "maxiter": 500},
    )
    return float(np.linalg.norm(found.x @ points))


def test_the_simplex_keeps_its_point_closest_to_the_origin() -> None:
    rng = np.random.default_rng(12)
    inside = 0
    for size in (2, 3, 4) * 60:
        points = rng.normal(size=(size, 3)) + rng.normal(size=3) * 0.5
        simplex, weights = np.zeros((4, 3)), np.zeros(4)
        simplex[:size] = points
        kept = reduce_simplex(simplex, size, weights)
        if kept == 0:  # the origin inside the tetrahedron
            inside += 1
            assert closest_of_hull(points) < 1e-6
            continue
        assert 1 <= kept <= size
        assert np.all(weights[:kept] > 0.0)
        assert weights[:kept].sum() == pytest.approx(1.0)
        for row in simplex[:kept]:  # the kept vertices are the given ones
            assert np.min(np.linalg.norm(points - row, axis=1)) == 0.0
        closest = weights[:kept] @ simplex[:kept]
        assert np.linalg.norm(closest) == pytest.approx(closest_of_hull(points), abs=1e-7)
    assert inside >= 3
