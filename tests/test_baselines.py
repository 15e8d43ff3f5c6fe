from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from planning import baselines
from planning.firefly import FireflySettings
from planning.planner import plan
from planning.scene import paper_scene

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
    factories: dict[str, Callable[[], baselines.Optimizer]] = {
        "pso": baselines.particle_swarm,
        "harmony": baselines.harmony_search,
        "de": baselines.differential_evolution,
    }
    optimiser = factories[name]()
    result = plan(paper_scene(1), robot, optimizer=optimiser)
    assert result.verification.accepted and result.metrics.min_clearance >= 0.1
    assert result.metrics.evaluations <= 2550


def test_rrt_connect_pipeline(robot: ck.Robot) -> None:
    pytest.importorskip("ompl")
    pytest.importorskip("toppra")
    from planning.sampling import plan_rrt_connect

    result = plan_rrt_connect(paper_scene(), robot, seed=0)
    assert result.success, result.reason
    assert result.min_clearance >= 0.1
    np.testing.assert_allclose(result.waypoints[0], ck.tcp_ik(robot, (0.5, 0.45, 0.25)), atol=1e-9)
    np.testing.assert_allclose(result.waypoints[-1], ck.tcp_ik(robot, (-0.5, 0.45, 0.25)), atol=1e-9)
    assert result.duration > 0 and result.path_length > 0


def test_benchmark_script_runs(tmp_path: Path) -> None:
    out = tmp_path / "bench.md"
    completed = subprocess.run(
        [
            sys.executable,
            str(ROOT / "scripts" / "bench_peers.py"),
            "--scenes",
            "1",
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
    assert "firefly (ours) + septic spline" in report and "| method | success |" in report
