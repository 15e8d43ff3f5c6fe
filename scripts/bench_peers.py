"""Benchmark against peers: the same objective, budget and scenes, side by side in one run.

1. Optimisers on the paper case's objective and budget (n = 50, 2550 evaluations), seeds
   0..9: our default search (the planner's seeds, n = 30, early stop, CMA-ES refinement) and our firefly with
   the paper's parameters against NiaPy's FireflyAlgorithm, PSO, harmony search, SciPy's
   differential evolution and CMA-ES. Targets: the paper-parameter firefly >= 10x faster
   than NiaPy's FA with an equal or better median fitness; our default search's median
   fitness at least as good as the best peer's. Then (1b) the same optimisers at equal
   budgets: the evaluations our default search spends before its early stop, 600, 1275 and
   2550, each optimiser's median fitness at each (quality at equal cost).
2. Planners on ``--scenes`` generated scenes (seeded; 0: none): the firefly planner, the same
   pipeline with each baseline optimiser, OMPL's RRT-Connect + simplification + TOPP-RA and
   pyroboplan's RRT-Connect + shortcutting + TOPP-RA.
   Every result is verified by the same certified continuous check. Target: our success
   rate >= RRT-Connect's.

Prints the tables and writes them as Markdown to ``--out``.
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.bench.ompl_rrt import plan_rrt_connect
from planning.bench.pyroboplan_rrt import plan_pyroboplan_rrt_connect
from planning.bench.scene_generator import generate_scenes
from planning.bench.toppra_timing import SamplingResult
from planning.cli.arguments import COUNT, SECONDS, SEED, integer_at_least
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import paper_scene
from planning.io.report import markdown_table
from planning.pipeline.objective import WaypointObjective
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem, with_planner
from planning.pipeline.scene import Scene
from planning.pipeline.search import planner_search
from planning.pipeline.seeding import SEEDINGS
from planning.pipeline.settings import DEFAULT_FIREFLY
from planning.search import baselines
from planning.search.optimizer import BatchObjective, Optimizer, SearchResult
from planning.warming import warm_up

FloatArray = NDArray[np.float64]
DEFAULT_SEARCH = "firefly (our defaults: seeded, n = 30, early stop, CMA-ES refinement)"
FULL_BUDGET = "the same with refine_stall: 0 (its refinement run to the budget)"


def optimisers(scene: Scene) -> dict[str, Optimizer]:
    settings = scene.planner.firefly
    found: dict[str, Optimizer] = {
        "firefly (ours)": baselines.firefly(settings),
        "PSO": baselines.particle_swarm(),
        "harmony search": baselines.harmony_search(),
        "differential evolution (scipy)": baselines.differential_evolution(),
    }
    peers: list[tuple[str, str, Callable[[], Optimizer]]] = [
        ("CMA-ES (cma)", "cma", baselines.cma_es),
        ("NiaPy FireflyAlgorithm", "niapy", lambda: baselines.niapy_firefly(settings)),
    ]
    for name, module, make in peers:
        try:
            __import__(module)
        except ImportError:
            print(f"  ({name}: not installed, skipped)")
            continue
        found[name] = make()
    return found


def default_search(robot: ck.Robot, scene: Scene, refine_stall: int | None = None) -> Optimizer:
    """Our default search on ``scene``'s objective: the planner's own, through its entry point.

    The scene with the planner's default search settings (:data:`DEFAULT_FIREFLY`, seeded
    with paths, CMA-ES refinement; ``refine_stall`` as that planner setting, 0 to run the
    refinement to the budget); each run begins as the planner's first attempt does (its
    seeding's ``first``: the seeds, whether one is feasible and the sampling planner's path,
    which decide whether the firefly explores; its streams seeded from ``rng``) and runs
    :func:`~planning.pipeline.search.planner_search`'s optimiser on the objective given.
    """
    changes = {**dataclasses.asdict(DEFAULT_FIREFLY), "seeding": "paths", "refine": "cma"}
    if refine_stall is not None:
        changes["refine_stall"] = refine_stall
    problem = build_problem(scene.with_planner(**changes), robot)

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        seeded = with_planner(problem, seed=int(rng.integers(2**31)))
        attempt = SEEDINGS[seeded.scene.planner.seeding].first(seeded)  # the planner's first attempt
        return planner_search(attempt.problem, attempt)(objective, lower, upper, budget, rng)

    return run


def paper_objective(robot: ck.Robot, scene: Scene) -> WaypointObjective:
    return build_problem(scene, robot).objective


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def optimiser_methods(robot: ck.Robot, scene: Scene) -> dict[str, Optimizer]:
    """Our default search, the same run to the budget, and :func:`optimisers`."""
    methods = {DEFAULT_SEARCH: default_search(robot, scene), FULL_BUDGET: default_search(robot, scene, 0)}
    methods.update(optimisers(scene))
    return methods


@dataclass(frozen=True)
class Runs:
    """Each method's runs at one budget, one entry per seed."""

    times: dict[str, list[float]]
    """Wall times [s]."""
    fitness: dict[str, list[float]]
    """Best values found."""
    spent: dict[str, list[int]]
    """Evaluations used."""

    def medians(self) -> dict[str, float]:
        """Each method's median fitness."""
        return {name: statistics.median(values) for name, values in self.fitness.items()}


def run_optimisers(
    methods: dict[str, Optimizer], objective: WaypointObjective, budget: int, seeds: int
) -> Runs:
    """Every method on ``objective`` with ``budget`` evaluations, seeds ``0..seeds-1``.

    The methods run interleaved, seed by seed, so that the machine's drift hits them alike.
    """
    runs = Runs(
        {name: [] for name in methods}, {name: [] for name in methods}, {name: [] for name in methods}
    )
    for seed in range(seeds):
        for name, optimiser in methods.items():
            started = time.perf_counter()
            result = optimiser(
                objective, objective.lower, objective.upper, budget, np.random.default_rng(seed)
            )
            runs.times[name].append(time.perf_counter() - started)
            runs.fitness[name].append(result.fitness)
            runs.spent[name].append(result.evaluations)
    return runs


def optimiser_table(
    runs: Runs, objective: WaypointObjective
) -> tuple[list[list[str]], dict[str, float], dict[str, float]]:
    """Rows of the optimiser table; each optimiser's median time ratio to ours and evaluations.

    ``objective``: the objective run (its feasibility rule counts the feasible runs).
    """
    times = runs.times
    ours = times["firefly (ours)"]  # the paper's parameters: the figure the NiaPy target is about
    # per seed, each method's time over ours in the same round; the median of those ratios
    ratios = {
        name: statistics.median(t / o for t, o in zip(times[name], ours, strict=True)) for name in times
    }
    rows = [
        [
            name,
            f"{statistics.median(times[name]):.3f} s",
            f"{ratios[name]:.1f}",
            f"{statistics.median(runs.fitness[name]):.4f}",
            f"{statistics.median(runs.spent[name]):.0f}",
            f"{int(objective.feasible(np.array(runs.fitness[name])).sum())}/{len(ours)}",
        ]
        for name in times
    ]
    return rows, ratios, {name: statistics.median(values) for name, values in runs.spent.items()}


def budget_table(at_budget: dict[int, dict[str, float]]) -> list[list[str]]:
    """Rows of each optimiser's median fitness, a column per budget of ``at_budget``, its best in bold."""
    best = {budget: min(medians.values()) for budget, medians in at_budget.items()}
    names = next(iter(at_budget.values()))
    return [
        [name]
        + [
            f"**{medians[name]:.3f}**" if medians[name] == best[budget] else f"{medians[name]:.3f}"
            for budget, medians in at_budget.items()
        ]
        for name in names
    ]


def sampling_method(
    robot: ck.Robot, planner: Callable[..., SamplingResult], time_limit_s: float
) -> Callable[[Scene], dict[str, float] | None]:
    """One of the sampling pipelines (OMPL's or pyroboplan's RRT-Connect) as a benchmark method."""

    def run(scene: Scene) -> dict[str, float] | None:
        result = planner(scene, robot, time_limit_s=time_limit_s, seed=scene.planner.seed)
        if not result.success:
            return None
        return {
            "time": result.planning_time_s,
            "duration": result.duration,
            "length": result.path_length,
            "jerk": result.max_abs_jerk,
            "clearance": result.min_clearance,
        }

    return run


def planner_rows(robot: ck.Robot, scenes: list[Scene], time_limit_s: float) -> list[list[str]]:
    methods: dict[str, Callable[[Scene], dict[str, float] | None]] = {}

    def pipeline(optimiser: Optimizer | None) -> Callable[[Scene], dict[str, float] | None]:
        def run(scene: Scene) -> dict[str, float] | None:
            try:
                result = plan(scene, robot, optimizer=optimiser)
            except (PlanningError, NoSolutionError):
                return None
            trajectory = result.trajectory
            dense = trajectory(np.linspace(0, trajectory.duration, 2001))
            length = float(np.linalg.norm(np.diff(dense / robot.limits.range, axis=0), axis=1).sum())
            jerk = max(
                float(np.max(np.abs(trajectory.extrema(3).minimum))),
                float(np.max(trajectory.extrema(3).maximum)),
            )
            return {
                "time": result.metrics.planning_time_s,
                "duration": result.metrics.duration_s,
                "length": length,
                "jerk": jerk,
                "clearance": result.metrics.min_clearance_m,
            }

        return run

    sample = scenes[0]
    for name, optimiser in optimisers(sample).items():
        methods[f"{name} + septic spline"] = pipeline(None if name == "firefly (ours)" else optimiser)
    # the planners import their peers when called: check that the peers are there first
    for label, planner, needs in (
        ("RRT-Connect (OMPL) + TOPP-RA", plan_rrt_connect, ("ompl", "toppra")),
        ("RRT-Connect (pyroboplan) + TOPP-RA", plan_pyroboplan_rrt_connect, ("pyroboplan", "toppra")),
    ):
        try:
            for name in needs:
                __import__(name)
        except ImportError:
            print(f"  ({' or '.join(needs)} not installed: {label} skipped)")
            continue
        methods[label] = sampling_method(robot, planner, time_limit_s)

    results: dict[str, list[dict[str, float] | None]] = {name: [] for name in methods}
    for scene in scenes:
        for name, method in methods.items():
            results[name].append(method(scene))
    ours = statistics.median([r["time"] for r in results[next(iter(results))] if r] or [float("nan")])
    rows: list[list[str]] = []
    for name, outcomes in results.items():
        ok = [r for r in outcomes if r is not None]

        def med(key: str, ok: list[dict[str, float]] = ok) -> float:
            return statistics.median([r[key] for r in ok]) if ok else float("nan")

        times = [r["time"] for r in ok]
        rows.append(
            [
                name,
                f"{len(ok)}/{len(outcomes)}",
                f"{med('time'):.3f} / {percentile(times, 90):.3f} s",
                f"{med('time') / ours:.2f}",
                f"{med('duration'):.2f} s",
                f"{med('length'):.3f}",
                f"{med('jerk'):.3g}",
                f"{med('clearance'):.3f} m",
            ]
        )
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--scenes", type=integer_at_least(0), default=50, help="generated scenes (default: 50; 0: none)"
    )
    parser.add_argument(
        "--seeds", type=COUNT, default=10, help="seeds of the optimiser comparison (default: 10)"
    )
    parser.add_argument("--scene-seed", type=SEED, default=0, help="seed of the scene generator (default: 0)")
    parser.add_argument(
        "--rrt-time", type=SECONDS, default=2.0, help="RRT-Connect time limit [s] (default: 2)"
    )
    parser.add_argument("--out", type=Path, default=Path("out/bench_peers.md"), help="Markdown report")
    args = parser.parse_args()
    robot = ck.load_cpr()
    print(f"compiled (or loaded) the numba kernels in {warm_up(robot):.1f} s; not part of any timing\n")

    scene = paper_scene()
    objective = paper_objective(robot, scene)
    budget = scene.planner.firefly.evaluations
    methods = optimiser_methods(robot, scene)
    print(
        f"1. Optimisers on the paper case's objective, budget {budget} evaluations, seeds 0..{args.seeds - 1}"
    )
    full = run_optimisers(methods, objective, budget, args.seeds)
    rows, ratios, spent = optimiser_table(full, objective)
    medians = full.medians()
    headers1 = (
        "optimiser",
        "median time",
        "time / ours (per seed)",
        "median fitness",
        "evaluations",
        "feasible",
    )
    print(markdown_table(rows, headers1))
    if "NiaPy FireflyAlgorithm" in ratios:
        ratio = ratios["NiaPy FireflyAlgorithm"]
        print(f"ours vs NiaPy's FA: {ratio:.1f}x faster, median of per-seed ratios (target >= 10x)")
    ours = (DEFAULT_SEARCH, FULL_BUDGET)
    peers = [name for name in medians if not name.startswith("firefly") and name not in ours]
    best = min(peers, key=medians.__getitem__)
    for name, label in zip(ours, ("our default search", "run to the budget"), strict=True):
        print(
            f"{label}: median fitness {medians[name]:.4f} in {spent[name]:.0f} evaluations, the best "
            f"peer's ({best}) {medians[best]:.4f} in {budget} "
            f"(target: ours <= theirs: {'met' if medians[name] <= medians[best] else 'NOT met'})"
        )

    budgets = sorted({int(spent[DEFAULT_SEARCH]), 600, 1275, budget})
    print(f"\n1b. The same at equal budgets: {', '.join(map(str, budgets))} evaluations (median fitness)")
    at_budget = {
        b: medians if b == budget else run_optimisers(methods, objective, b, args.seeds).medians()
        for b in budgets
    }
    rows1b = budget_table(at_budget)
    headers1b = ("optimiser", *(f"{b} evaluations" for b in budgets))
    print(markdown_table(rows1b, headers1b))
    for name, label in zip(ours, ("our default search", "run to the budget"), strict=True):
        wins = [b for b, at in at_budget.items() if at[name] <= min(at[peer] for peer in peers)]
        print(f"{label}: at least as good as every peer at {len(wins)} of {len(budgets)} budgets {wins}")

    report = (
        "# Benchmark against peers\n\n## Optimisers (paper case objective)\n\n"
        + markdown_table(rows, headers1)
        + "\n\n## Optimisers at equal budgets (median fitness)\n\n"
        + markdown_table(rows1b, headers1b)
        + "\n"
    )
    if args.scenes:
        report += planners_section(robot, args.scenes, args.scene_seed, args.rrt_time)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(report)
    print(f"\nwrote {args.out}")


def planners_section(robot: ck.Robot, count: int, scene_seed: int, rrt_time_s: float) -> str:
    """Part 2: prints the planner table and returns it as a Markdown section."""
    print(f"\n2. Planners on {count} generated scenes (generator seed {scene_seed}), all verified")
    scenes = generate_scenes(count, scene_seed, robot)
    headers2 = (
        "method",
        "success",
        "median / p90 time",
        "time / ours",
        "duration",
        "path length",
        "max abs jerk",
        "min clearance",
    )
    rows2 = planner_rows(robot, scenes, rrt_time_s)
    print(markdown_table(rows2, headers2))
    return f"\n## Planners ({count} generated scenes)\n\n" + markdown_table(rows2, headers2) + "\n"


if __name__ == "__main__":
    main()
