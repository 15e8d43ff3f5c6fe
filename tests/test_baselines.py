from __future__ import annotations

import itertools
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan
from planning.search import baselines
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import Optimizer

ROOT = Path(__file__).resolve().parent.parent


def sphere(x: np.ndarray) -> np.ndarray:
    return np.asarray(np.sum((x - 0.3) ** 2, axis=1))


def optimiser_factories() -> list[tuple[str, object]]:
    factories: list[tuple[str, object]] = [
        ("firefly", lambda: baselines.firefly(FireflySettings(fireflies=20, alpha=0.3, beta0=1.0))),
        ("pso", baselines.particle_swarm),
        ("harmony", baselines.harmony_search),
        ("de", baselines.differential_evolution),
        ("cma", baselines.cma_es),
        ("niapy", lambda: baselines.niapy_firefly(FireflySettings(fireflies=20, alpha=0.3, beta0=1.0))),
    ]
    return factories


@pytest.mark.parametrize(
    ("name", "factory"), optimiser_factories(), ids=[n for n, _ in optimiser_factories()]
)
def test_budget_bounds_and_progress(name: str, factory: object) -> None:
    if name in ("cma", "niapy"):
        pytest.importorskip("cma" if name == "cma" else "niapy")
    lower, upper = -np.ones(5), 2 * np.ones(5)
    seen: list[np.ndarray] = []

    def objective(x: np.ndarray) -> np.ndarray:
        seen.append(np.atleast_2d(x).copy())
        return sphere(x)

    budget = 1000
    result = factory()(objective, lower, upper, budget, np.random.default_rng(0))  # type: ignore[operator]
    points = np.vstack(seen)
    assert len(points) == result.evaluations <= budget
    assert result.evaluations >= 0.9 * budget
    assert np.all(points >= lower) and np.all(points <= upper)
    assert result.fitness == pytest.approx(float(np.min(sphere(points))))
    assert result.fitness < 0.05  # far better than the 1.45 of a random point on average
    again = factory()(sphere, lower, upper, budget, np.random.default_rng(0))  # type: ignore[operator]
    assert again.fitness == result.fitness  # seeded


@pytest.mark.parametrize("name", ["pso", "harmony", "de"])
def test_baselines_plan_the_paper_case(robot: ck.Robot, name: str) -> None:
    factories: dict[str, Callable[[], Optimizer]] = {
        "pso": baselines.particle_swarm,
        "harmony": baselines.harmony_search,
        "de": baselines.differential_evolution,
    }
    optimiser = factories[name]()
    result = plan(paper_scene(1), robot, optimizer=optimiser)
    assert result.verification.accepted and result.metrics.min_clearance_m >= 0.1
    assert result.metrics.evaluations <= 2550


@pytest.mark.parametrize("peer", ["ompl", "pyroboplan"])
def test_rrt_connect_pipelines(robot: ck.Robot, peer: str) -> None:
    pytest.importorskip(peer)
    pytest.importorskip("toppra")
    if peer == "ompl":
        from planning.bench.ompl_rrt import plan_rrt_connect as planner
    else:
        from planning.bench.pyroboplan_rrt import plan_pyroboplan_rrt_connect as planner

    state = np.random.get_state()
    result = planner(paper_scene(), robot, seed=0)
    after = np.random.random(8)  # the global generator is left where it was
    np.random.set_state(state)
    np.testing.assert_array_equal(after, np.random.random(8))
    assert result.success, result.reason
    assert result.min_clearance >= 0.1
    np.testing.assert_allclose(result.waypoints[0], ck.tcp_ik(robot, (0.5, 0.45, 0.25)), atol=1e-9)
    np.testing.assert_allclose(result.waypoints[-1], ck.tcp_ik(robot, (-0.5, 0.45, 0.25)), atol=1e-9)
    assert result.duration > 0 and result.path_length > 0


@pytest.mark.slow
@pytest.mark.parametrize("scenes", [1, 0])
def test_benchmark_script_runs(tmp_path: Path, scenes: int) -> None:
    """The script writes its report, with the planners' table unless ``--scenes 0``."""
    out = tmp_path / "bench.md"
    completed = subprocess.run(
        [
            sys.executable,
            str(ROOT / "scripts" / "bench_peers.py"),
            "--scenes",
            str(scenes),
            "--seeds",
            "1",
            "--out",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert completed.returncode == 0, completed.stderr[-2000:]
    report = out.read_text()
    assert "## Optimisers at equal budgets" in report and "| 2550 evaluations |" in report
    planners = "firefly (ours) + septic spline" in report and "| method | success |" in report
    assert planners == bool(scenes)


def test_shortcut_path_keeps_ends_and_checks_every_new_segment() -> None:
    from planning.bench.pyroboplan_rrt import shortcut_path

    def clear(a: np.ndarray, b: np.ndarray) -> bool:
        """A wall at x = 0.5 blocks |y| < 0.2: is the segment a-b free of it?"""
        if (a[0] - 0.5) * (b[0] - 0.5) > 0:
            return True  # both on one side of the wall
        y = a[1] + (0.5 - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
        return bool(abs(y) >= 0.2)

    checked: list[tuple[tuple[float, ...], tuple[float, ...]]] = []

    def recorded(a: np.ndarray, b: np.ndarray) -> bool:
        checked.append((tuple(a), tuple(b)))
        return clear(a, b)

    # a clear zigzag over the wall; the straight line from start to goal is blocked
    zigzag = np.array([[0.0, 0.0], [0.2, 0.6], [0.35, 0.1], [0.5, 0.6], [0.65, 0.1], [0.8, 0.6], [1.0, 0.0]])
    assert all(clear(a, b) for a, b in itertools.pairwise(zigzag))
    assert not clear(zigzag[0], zigzag[-1])

    path = shortcut_path(zigzag, recorded, np.random.default_rng(0), attempts=200)
    np.testing.assert_array_equal(path[0], zigzag[0])
    np.testing.assert_array_equal(path[-1], zigzag[-1])

    def length(polyline: np.ndarray) -> float:
        return float(np.linalg.norm(np.diff(polyline, axis=0), axis=1).sum())

    assert length(path) < 0.6 * length(zigzag)
    assert length(path) >= 2 * np.hypot(0.5, 0.2) - 1e-12  # no shorter way around the wall
    # every segment of the result lies on one of the input's or on one that was checked clear
    known = [(np.asarray(a), np.asarray(b)) for a, b in itertools.pairwise(zigzag)]
    known += [(np.array(a), np.array(b)) for a, b in checked if clear(np.array(a), np.array(b))]

    def within(point: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
        s = float(np.clip((point - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0))
        return bool(np.linalg.norm(a + s * (b - a) - point) < 1e-9)

    for p, q in itertools.pairwise(path):
        assert any(within(p, a, b) and within(q, a, b) for a, b in known)
        assert clear(p, q)


def test_the_peers_timing_stays_within_the_joint_ranges_along_a_limit(robot: ck.Robot) -> None:
    """A path that runs along d2's lower limit: the clamped cubic dips below it, PCHIP does not."""
    pytest.importorskip("toppra")
    import dataclasses
    import time

    from planning.bench.toppra_timing import PchipPath, _geometric_path, time_and_verify

    waypoints = np.array(
        [
            [-1.0, 0.3, 0.2, 0.0, 0.0],
            [-0.5, 0.0, 0.2, 0.0, 0.0],
            [0.5, 0.0, 0.2, 0.0, 0.0],
            [1.0, 0.3, 0.2, 0.0, 0.0],
        ]
    )
    s = np.array([0.0, 0.3, 0.7, 1.0])
    cubic = _geometric_path(s[[0, 3]], waypoints[[0, 3]], robot.limits)  # no vertex on a limit: the cubic
    assert not isinstance(cubic, PchipPath)
    along = _geometric_path(s, waypoints, robot.limits)
    assert isinstance(along, PchipPath)
    q = along(np.linspace(0.0, 1.0, 1001))
    assert q[:, 1].min() >= 0.0  # the cubic's would go below 0 between the two vertices at 0
    np.testing.assert_allclose(along(s), waypoints, atol=1e-12)
    scene = dataclasses.replace(paper_scene(), obstacles=())
    result = time_and_verify(robot, ck.CollisionWorld(robot, []), scene, waypoints, time.perf_counter())
    assert result.success, result.reason
