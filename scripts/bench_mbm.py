"""MotionBenchMaker: our planner beside OMPL's RRT-Connect pipeline, problem by problem, in one run.

    python scripts/bench_mbm.py [--robots panda ur5] [--classes ...] [--limit N [--sample-seed S]]
                                [--timeout S] [--out DIR] [--workers N] [--time-limit S]
    python scripts/bench_mbm.py --scenes out/arms/ur3 out/arms/panda/*.yaml [--timeout S] [--out DIR]

Each problem goes the way a user's does (``import-moveit``, :mod:`planning.io.moveit_import`,
margins 0 as in MoveIt), then, alternating, is planned warm by

- ours: :func:`planning.pipeline.planner.plan` with the scene's default settings and a time
  limit (``time_limit_s``, ``--time-limit``, default 0.8 of the timeout: what a user with that
  budget sets; the plan returns what it verified by then), in a worker process (robot loaded,
  kernels compiled) stopped after ``--timeout`` seconds;
- OMPL RRT-Connect + simplification + TOPP-RA (:mod:`planning.peers.ompl_rrt`) on the same
  collision model (obstacles and self pairs), 1 s per attempt, new seeds up to ``--timeout``.

Both are verified by the same certified checks. Printed per class: problems whose start and
goal are valid in our model, solved by each, median and p95 warm planning time of each over
the problems it solved and the ratio of those medians, then the ratio of the medians over the
problems both solved (the same problems) and over every valid problem (a failure counted at
the time it took, up to the timeout), ours' median duration over Ruckig's jerk-limited bound
for the straight line, OMPL's median jerk over the limit, how many of OMPL's trajectories
drive a joint's torque beyond its effort limit (RNEA every millisecond with the scene's
payload, untimed; TOPP-RA's timing knows neither jerk nor torque limits, ours keeps both), and
how many of ours pass ``cpr-plan check`` (the trajectory file read back and verified anew,
untimed). Rows go to
``DIR/mbm.csv``, the table as markdown to ``DIR/mbm.md``. Needs the ``bench`` extra; the
problems are downloaded once (:mod:`planning.io.mbm`).

``--limit N`` takes the first N problems of each class, those the development looked at most;
with ``--sample-seed S`` it draws N of each class at random instead (the same seed, the same
problems): a held-out sample.

Each planner runs in its own worker process; ``--workers N`` plans N problems at once, ours'
parallel collision checks then on a share of the cores each (on a 2-core machine both
planners share the cores, and both take longer: compare the ratios with a run of one worker).
``--scenes FILE_OR_FOLDER ...`` runs scene files instead (a folder: its ``*.yaml`` files), of
any robot (``generate_arm_scenes.py``'s, a user's own; the bundled CPR where a scene names
none), the same way; rows are grouped by the file's folder (the "robot" column) and its name
without a trailing ``_<number>`` (the "class"). Every scene and robot is loaded before
anything runs: a missing or malformed file, or a robot that does not load, is named in one
line.
"""

from __future__ import annotations

import argparse
import csv
import itertools
import multiprocessing
import os
import queue
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from pathlib import Path
from typing import Any

import numpy as np

import cpr_kin as ck
from planning.batch import scene_files
from planning.cli.arguments import COUNT, SECONDS
from planning.cli.problem_selection import add_selection, check_selection, selected_problems
from planning.errors import NoSolutionError, PlanningError
from planning.io.mbm import endpoint_violations, import_problem
from planning.io.scene_file import load_scene
from planning.io.trajectory_io import trajectory_json
from planning.outcome import classify

TIME_LIMIT_SHARE = 0.8
"""Our planner's default ``time_limit_s`` as a share of ``--timeout``: room to time and verify."""
_ROBOTS: dict[str, ck.Robot] = {}


def _robot(scene_path: str) -> tuple[Any, ck.Robot]:
    """The scene file's scene and robot (the bundled CPR where it names none, as ``cpr-plan plan``).

    Each robot is loaded and its kernels compiled once per process.
    """
    scene = load_scene(Path(scene_path))
    key = str(scene.robot) if scene.robot is not None else "cpr"
    if key not in _ROBOTS:
        from planning.pipeline.planner import warm_up

        _ROBOTS[key] = scene.robot.load() if scene.robot is not None else ck.load_cpr()
        warm_up(_ROBOTS[key])
    return scene, _ROBOTS[key]


def ours(scene_path: str, time_limit_s: float, threads: int | None = None) -> dict[str, Any]:
    """Our planner on one scene file, warm (in the worker): success, time, duration over Ruckig's bound.

    ``threads``: of its parallel collision checks (``None``: the planner's default, up to 2).
    """
    from planning.peers.ruckig_bound import free_space_bound
    from planning.pipeline.planner import plan

    scene, robot = _robot(scene_path)
    scene = scene.with_planner(time_limit_s=time_limit_s)
    started = time.perf_counter()
    try:
        result = plan(scene, robot, threads=threads)
    except NoSolutionError as exc:
        return {"ok": False, "time_s": time.perf_counter() - started, "why": str(exc)[:100]}
    elapsed = time.perf_counter() - started
    bound = free_space_bound(result.problem)
    return {
        "ok": result.verification.accepted,
        "time_s": elapsed,
        "duration_s": result.trajectory.duration,
        "over_bound": result.trajectory.duration / bound,
        "file": trajectory_json(result),
    }


def passes_check(scene_path: str, trajectory_text: str) -> bool:
    """``cpr-plan check``'s verdict on a trajectory file (in the worker, untimed).

    The file read back and verified against the scene file on a problem built anew, as the
    command does: certified clearance to every obstacle and between the robot's own pairs,
    joint ranges, velocity, acceleration and jerk limits, and the ends.
    """
    from planning.io.trajectory_reader import read_trajectory
    from planning.pipeline.problem import build_problem
    from planning.pipeline.verification import verify_for_scene

    scene, robot = _robot(scene_path)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "trajectory.json"
        path.write_text(trajectory_text)
        document = read_trajectory(path)
    problem = build_problem(scene, robot)
    try:
        verification = verify_for_scene(problem, document.trajectory, document.joint_names)
    except PlanningError:  # the file's joints are not the robot's
        return False
    return not verification.problems


def warm(scene_path: str) -> None:
    """Load the scene's robot and compile the kernels in this process (untimed)."""
    _robot(scene_path)


def warm_peer(scene_path: str) -> None:
    """:func:`warm`, and import OMPL's pipeline (untimed).

    Its first call in a process would otherwise count the imports, TOPP-RA's above all:
    0.32 s against 0.035 s warm on the bundled shelf.
    """
    from planning.peers.ompl_rrt import import_peer

    warm(scene_path)
    import_peer()


def theirs(scene_path: str, timeout_s: float) -> dict[str, Any]:
    """OMPL's pipeline on one scene file, warm: 1 s attempts with new seeds until ``timeout_s``."""
    from planning.peers.ompl_rrt import plan_rrt_connect

    scene, robot = _robot(scene_path)
    started = time.perf_counter()
    seed = 0
    while time.perf_counter() - started < timeout_s:
        left_s = timeout_s - (time.perf_counter() - started)
        try:
            result = plan_rrt_connect(scene, robot, min(1.0, left_s), seed)
        except NoSolutionError as exc:  # the problem itself has none (a start the motors cannot hold)
            return {"ok": False, "time_s": time.perf_counter() - started, "why": str(exc)[:100]}
        if result.success:
            elapsed = time.perf_counter() - started
            return {
                "ok": True,
                "time_s": elapsed,
                "duration_s": result.duration,
                "jerk": result.jerk_over_limit,
                "torque": torque_over_limit(scene, robot, result.timed, result.duration),
            }
        seed += 1
    return {"ok": False, "time_s": time.perf_counter() - started}


def torque_over_limit(scene: Any, robot: ck.Robot, timed: Any, duration_s: float) -> float:
    """The largest ``|torque| / effort`` of a joint along a timed trajectory (RNEA every ms, untimed).

    ``timed(t, order)``: positions, velocities, accelerations at times ``t`` [s]; the scene's
    payload and ``torque_scale`` as ours are held to. 0 where no joint has an effort limit.
    """
    dynamics = ck.robot_dynamics(robot, scene.payload, scene.torque_scale)
    times = np.union1d(np.arange(0.0, duration_s, 1e-3), [duration_s])
    torques = dynamics.torques(*(np.asarray(timed(times, order)) for order in (0, 1, 2)))
    return float(dynamics.utilisation(torques).max())


def valid(scene_path: Path) -> str | None:
    """Why the scene's start or goal is not valid in our model, or ``None``."""
    scene, robot = _robot(str(scene_path))
    return next(iter(endpoint_violations(scene, robot)), None)


def summary(row: dict[str, Any]) -> str:
    """One problem's outcome for the progress line."""
    ours_text = f"ours {row.get('ours_ok')} {row.get('ours_time_s', 0):.2f} s"
    return f"{ours_text}, ompl {row.get('ompl_ok')} {row.get('ompl_time_s', 0):.2f} s"


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def median_ratio(mine: list[float], peer: list[float]) -> float:
    """Median of ``mine`` over median of ``peer`` (nan when either is empty)."""
    return statistics.median(mine) / statistics.median(peer) if mine and peer else float("nan")


class Lane:
    """One problem at a time: ours in a worker process (killed at the timeout), OMPL's in another."""

    def __init__(self, context: Any, threads: int | None = None) -> None:
        self.context, self.threads = context, threads
        self.ours, self.theirs = self._pool(), self._pool()

    def _pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(1, mp_context=self.context)

    def run(self, path: Path, timeout_s: float, time_limit_s: float) -> dict[str, Any]:
        """Both planners on the scene file ``path``, warm: the row's ``ours_*`` and ``ompl_*`` values."""
        row: dict[str, Any] = {}
        self.ours.submit(warm, str(path)).result()  # loaded once per robot and process, untimed
        future = self.ours.submit(ours, str(path), time_limit_s, self.threads)
        try:
            found = future.result(timeout=timeout_s)
            text = found.pop("file", None)
            row |= {f"ours_{k}": v for k, v in found.items()}
            if text is not None:
                row["ours_checked"] = self.ours.submit(passes_check, str(path), text).result()
        except FutureTimeout:
            row |= {"ours_ok": False, "ours_time_s": timeout_s, "ours_why": "timeout"}
            self._kill(self.ours)
            self.ours = self._pool()
        self.theirs.submit(warm_peer, str(path)).result()
        row |= {f"ompl_{k}": v for k, v in self.theirs.submit(theirs, str(path), timeout_s).result().items()}
        return row

    def close(self) -> None:
        """Stop both worker processes."""
        for pool in (self.ours, self.theirs):
            pool.shutdown(cancel_futures=True)

    @staticmethod
    def _kill(pool: ProcessPoolExecutor) -> None:
        for process in list(getattr(pool, "_processes", {}).values()):
            process.kill()
        pool.shutdown(wait=False, cancel_futures=True)


def cases(args: argparse.Namespace) -> Iterator[tuple[str, str, int, Path]]:
    """``(robot, class, number, scene file)`` of each problem: MotionBenchMaker's, or ``--scenes``."""
    if args.scenes:
        for path in scene_paths(args.scenes):
            group, _, number = path.stem.rpartition("_")
            if not (group and number.isdigit()):
                group, number = path.stem, "0"
            yield path.resolve().parent.name, group, int(number), path
        return
    for robot_name in args.robots:
        for problem in selected_problems(args, robot_name):
            path = args.out / "scenes" / robot_name / f"{problem.name}.yaml"
            import_problem(problem, path)
            yield robot_name, problem.problem_class, problem.index, path


def scene_paths(given: list[Path]) -> list[Path]:
    """The scene files of ``--scenes``: each file as given, each folder's ``*.yaml`` files by name."""
    return [found for path in given for found in (scene_files(path) if path.is_dir() else [path])]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_selection(parser)
    parser.add_argument("--timeout", type=SECONDS, default=10.0, help="seconds per problem and planner")
    parser.add_argument(
        "--time-limit",
        type=SECONDS,
        help=f"our planner's time_limit_s [s] (default: {TIME_LIMIT_SHARE:g} of --timeout)",
    )
    parser.add_argument(
        "--scenes",
        nargs="+",
        type=Path,
        help="scene files or folders of them to run instead of MotionBenchMaker's (any robot)",
    )
    parser.add_argument(
        "--workers", type=COUNT, default=1, help="problems planned at once (each by both planners in turn)"
    )
    parser.add_argument("--out", type=Path, default=Path("out/bench_mbm"))
    args = parser.parse_args()
    check_selection(parser, args)
    if args.time_limit is not None and not 0 < args.time_limit <= args.timeout:
        parser.error(f"--time-limit {args.time_limit:g} s must be in (0, --timeout = {args.timeout:g}] s")
    time_limit_s = args.time_limit or TIME_LIMIT_SHARE * args.timeout
    try:  # every scene and robot loaded before anything runs: a bad file is one line
        chosen = list(cases(args))
        rows: list[dict[str, Any]] = [
            {"robot": robot, "class": group, "problem": index, "invalid": valid(path) or ""}
            for robot, group, index, path in chosen
        ]
    except Exception as exc:  # bad input is named in one line (the project's one rule for it)
        outcome = classify(exc)
        if outcome.status != "invalid":
            raise
        parser.error(outcome.message)
    args.out.mkdir(parents=True, exist_ok=True)
    context = multiprocessing.get_context("spawn")
    lanes: queue.Queue[Lane] = queue.Queue()
    # N lanes share the cores: ours' parallel checks get a share each (oversubscribed, they slow
    # ours far more than OMPL's one-state checks, and the ratio with it: docs/benchmarks.md)
    threads = None if args.workers == 1 else max(1, (os.cpu_count() or 1) // args.workers)
    for _ in range(args.workers):
        lanes.put(Lane(context, threads))
    finished = itertools.count(1)

    def solve(number: int) -> None:
        row, path = rows[number], chosen[number][3]
        if not row["invalid"]:
            lane = lanes.get()
            try:
                row |= lane.run(path, args.timeout, time_limit_s)
            finally:
                lanes.put(lane)
        mark = "-" if row["invalid"] else summary(row)
        print(f"[{next(finished)}/{len(chosen)}] {row['robot']} {path.stem}: {mark}", flush=True)

    with ThreadPoolExecutor(args.workers) as pool:
        list(pool.map(solve, range(len(chosen))))
    while not lanes.empty():
        lanes.get().close()
    keys = sorted({k for row in rows for k in row})
    with (args.out / "mbm.csv").open("w", newline="") as out:
        writer = csv.DictWriter(out, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)
    print(f"\n{'robot':6s} {'class':17s} {'valid':>5s} {'ours':>4s} {'ompl':>4s}", end="")
    print(f"  {'ours med/p95 s':>15s}  {'ompl med/p95 s':>15s}  ratio  both   all  dur/bound", end="")
    print("  ompl jerk/lim  ompl >effort  checked")
    drawn = f" drawn with seed {args.sample_seed}" if args.sample_seed is not None and not args.scenes else ""
    report = [
        f"{'Scene files' if args.scenes else f'MotionBenchMaker, {args.limit or 100} problem(s) per class'}"
        f"{drawn}, "
        f"timeout {args.timeout:g} s (ours: time_limit_s {time_limit_s:g} s), "
        "warm (`scripts/bench_mbm.py`)",
        "",
        "| robot | class | valid | solved ours | solved OMPL | ours median (p95) [s] | OMPL median (p95) [s] "
        "| ratio | ratio, both solved | ratio, all | ours duration / Ruckig bound | OMPL jerk / limit "
        "| OMPL beyond an effort limit | ours passing `check` |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for robot_name in dict.fromkeys(r["robot"] for r in rows):
        for problem_class in [*dict.fromkeys(r["class"] for r in rows if r["robot"] == robot_name), "all"]:
            group = [r for r in rows if r["robot"] == robot_name and problem_class in ("all", r["class"])]
            group = [r for r in group if not r["invalid"]]
            if not group:
                continue
            mine = [r["ours_time_s"] for r in group if r.get("ours_ok")]
            peer = [r["ompl_time_s"] for r in group if r.get("ompl_ok")]
            bounds = [r["ours_over_bound"] for r in group if r.get("ours_ok")]
            jerks = [r["ompl_jerk"] for r in group if r.get("ompl_ok")]
            ratio = median_ratio(mine, peer)
            both = [r for r in group if r.get("ours_ok") and r.get("ompl_ok")]
            ratio_both = median_ratio([r["ours_time_s"] for r in both], [r["ompl_time_s"] for r in both])
            ratio_all = median_ratio([r["ours_time_s"] for r in group], [r["ompl_time_s"] for r in group])
            checked = sum(1 for r in group if r.get("ours_checked"))
            beyond = sum(1 for r in group if r.get("ompl_ok") and r["ompl_torque"] > 1.0 + 1e-9)
            print(
                f"{robot_name:6s} {problem_class:17s} {len(group):5d} {len(mine):4d} {len(peer):4d}  "
                f"{percentile(mine, 50):6.2f} / {percentile(mine, 95):6.2f}  "
                f"{percentile(peer, 50):6.2f} / {percentile(peer, 95):6.2f}"
                f"  {ratio:5.2f} {ratio_both:5.2f} {ratio_all:5.2f}"
                f"  {percentile(bounds, 50):9.3f}  {percentile(jerks, 50):13.1f}  {beyond:11d}  {checked:7d}"
            )
            report.append(
                f"| {robot_name} | {problem_class} | {len(group)} | {len(mine)} | {len(peer)} "
                f"| {percentile(mine, 50):.2f} ({percentile(mine, 95):.2f}) "
                f"| {percentile(peer, 50):.2f} ({percentile(peer, 95):.2f}) | {ratio:.2f} "
                f"| {ratio_both:.2f} ({len(both)}) | {ratio_all:.2f} "
                f"| {percentile(bounds, 50):.3f} | {percentile(jerks, 50):.1f} | {beyond} | {checked} |"
            )
    (args.out / "mbm.md").write_text("\n".join(report) + "\n")
    print(f"\nrows: {args.out / 'mbm.csv'}; table: {args.out / 'mbm.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
