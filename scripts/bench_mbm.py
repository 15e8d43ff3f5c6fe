"""MotionBenchMaker: our planner beside a peer's RRT-Connect pipeline, problem by problem, in one run.

    python scripts/bench_mbm.py [--robots panda ur5] [--classes ...] [--limit N [--sample-seed S]]
                                [--timeout S] [--out DIR] [--workers N] [--time-limit S]
                                [--peer ompl|roboplan]
    python scripts/bench_mbm.py --scenes out/arms/ur3 out/arms/panda/*.yaml [--timeout S] [--out DIR]

Each problem goes the way a user's does (``import-moveit``, :mod:`planning.io.moveit_import`,
margins 0 as in MoveIt), then, alternating, is planned warm by

- ours: :func:`planning.pipeline.planner.plan` with the scene's default settings and a time
  limit (``time_limit_s``, ``--time-limit``, default 0.8 of the timeout: what a user with that
  budget sets; the plan returns what it verified by then), in a worker process (robot loaded,
  kernels compiled) stopped after ``--timeout`` seconds;
- the peer (``--peer``), on the same collision model (obstacles and self pairs): OMPL's
  RRT-Connect + simplification + TOPP-RA through Python callbacks
  (:mod:`planning.bench.ompl_rrt`), 1 s per attempt, new seeds up to ``--timeout`` (the
  default); or roboplan's RRT-Connect + shortcutting + TOPP-RA, compiled
  (:mod:`planning.bench.roboplan_rrt`), one search of up to ``--timeout``, whose path is then
  checked, untimed, by our certified checks: the table counts the paths that fail them at the
  scene's steps (as ``cpr-plan check``) and, in brackets, those that fail even at a tenth of
  them (in contact, or within half a millimetre of it).

Printed per class: problems whose start and goal are valid in our model, solved by each,
median and p95 warm planning time of each over the problems it solved and the ratio of those
medians, then the ratio of the medians over the problems both solved (the same problems) and
over every valid problem (a failure counted at the time it took, up to the timeout), each
one's median duration over Ruckig's jerk-limited bound for the straight line, the peer's
median jerk over the limit, how many of the peer's trajectories drive a joint's torque beyond
its effort limit (RNEA every millisecond with the scene's payload, untimed; TOPP-RA's timing
knows neither jerk nor torque limits, ours keeps both), how many of ours pass ``cpr-plan
check`` (the trajectory file read back and verified anew, untimed), and how many of the
peer's paths fail our checks (OMPL's are verified in its pipeline: none). Rows go to
``DIR/mbm.csv``, the table as markdown to ``DIR/mbm.md``. Needs the ``bench`` extra; the
problems are downloaded once (:mod:`planning.bench.mbm`).

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
line. A robot or scene the peer cannot take (roboplan 0.7.0 refuses the Z1 of
example-robot-data, one of whose links shares its name with a joint) leaves the problem
unsolved by the peer, its reason on the progress line and in the rows (``<peer>_why``), and
out of the ratio over every problem; ours is planned and counted all the same.
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
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import cpr_kin as ck
from cpr_kin.common.names import one_line
from planning.bench.mbm import endpoint_violations
from planning.bench.problem_selection import add_selection, check_selection, selected_cases
from planning.cli.arguments import COUNT, SECONDS
from planning.errors import NoSolutionError, PlanningError
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
        from planning.warming import warm_up

        _ROBOTS[key] = scene.robot.load() if scene.robot is not None else ck.load_cpr()
        warm_up(_ROBOTS[key])
    return scene, _ROBOTS[key]


def ours(scene_path: str, time_limit_s: float, threads: int | None = None) -> dict[str, Any]:
    """Our planner on one scene file, warm (in the worker): success, time, duration over Ruckig's bound.

    ``threads``: of its parallel collision checks (``None``: the planner's default, one on 2 cores).
    """
    from planning.bench.ruckig_bound import free_space_bound
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
        verification = verify_for_scene(
            problem, document.trajectory, document.joint_names, document.certified_step_m
        )
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
    from planning.bench.ompl_rrt import import_peer

    warm(scene_path)
    import_peer()


def theirs(scene_path: str, timeout_s: float) -> dict[str, Any]:
    """OMPL's pipeline on one scene file, warm: 1 s attempts with new seeds until ``timeout_s``."""
    from planning.bench.ompl_rrt import plan_rrt_connect

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
            from planning.bench.ruckig_bound import free_space_bound
            from planning.pipeline.problem import build_problem

            return {
                "ok": True,
                "time_s": elapsed,
                "duration_s": result.duration,
                "over_bound": result.duration / free_space_bound(build_problem(scene, robot)),
                "jerk": result.jerk_over_limit,
                "torque": torque_over_limit(scene, robot, result.timed, result.duration),
            }
        seed += 1
    return {"ok": False, "time_s": time.perf_counter() - started}


_PEER_SCENES: dict[str, Any] = {}


def warm_roboplan(scene_path: str) -> None:
    """:func:`warm`, and roboplan's scene of the file with our collision model, built once (untimed)."""
    from planning.bench.roboplan_rrt import RoboplanPeer

    scene, robot = _robot(scene_path)
    if scene_path not in _PEER_SCENES:
        _PEER_SCENES.clear()  # one problem at a time
        _PEER_SCENES[scene_path] = RoboplanPeer(scene, robot)


def theirs_roboplan(scene_path: str, timeout_s: float) -> dict[str, Any]:
    """Roboplan on one scene file, warm: RRT-Connect within ``timeout_s``, shortcutting, TOPP-RA.

    Untimed after it: the duration over Ruckig's bound, the jerk and torques of its trajectory
    (roboplan's samples, linearly interpolated), and our certified checks of its path.
    """
    from planning.bench.ruckig_bound import free_space_bound
    from planning.bench.toppra_timing import sampled_jerk

    scene, robot = _robot(scene_path)
    peer = _PEER_SCENES[scene_path]
    result = peer.plan(timeout_s, seed=0)
    if not result.success:
        return {"ok": False, "time_s": result.planning_time_s, "why": result.reason}
    times, *values = result.samples

    def timed(t: np.ndarray, order: int) -> np.ndarray:
        return np.column_stack([np.interp(t, times, column) for column in values[order].T])

    jerk = np.abs(sampled_jerk(times, values[2])) / robot.limits.jerk
    return {
        "ok": True,
        "time_s": result.planning_time_s,
        "duration_s": result.duration_s,
        "over_bound": result.duration_s / free_space_bound(peer.problem),
        "jerk": float(jerk.max()) if len(jerk) else 0.0,
        "torque": torque_over_limit(scene, robot, timed, result.duration_s),
        "checked": result.certified,
        "clear": result.certified_fine,
    }


@dataclass(frozen=True)
class Peer:
    """A peer planner of the benchmark: its name (the rows' prefix), label and worker functions."""

    name: str
    label: str
    warm: Callable[[str], None]
    run: Callable[[str, float], dict[str, Any]]


PEERS = {
    "ompl": Peer("ompl", "OMPL", warm_peer, theirs),
    "roboplan": Peer("roboplan", "roboplan", warm_roboplan, theirs_roboplan),
}
"""The peers ``--peer`` chooses from: OMPL's RRT-Connect through Python callbacks, roboplan's in C++."""


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


def summary(row: dict[str, Any], peer: str) -> str:
    """One problem's outcome for the progress line (a peer that could not run it: why)."""
    ours_text = f"ours {row.get('ours_ok')} {row.get('ours_time_s', 0):.2f} s"
    peer_time_s = row.get(f"{peer}_time_s", 0)
    if not np.isfinite(peer_time_s):
        return f"{ours_text}, {peer} could not run it ({row.get(f'{peer}_why')})"
    return f"{ours_text}, {peer} {row.get(f'{peer}_ok')} {peer_time_s:.2f} s"


def percentile(values: list[float], q: float) -> float:
    return float(np.percentile(values, q)) if values else float("nan")


def median_ratio(mine: list[float], peer: list[float]) -> float:
    """Median of ``mine`` over median of ``peer`` (nan when either is empty)."""
    return statistics.median(mine) / statistics.median(peer) if mine and peer else float("nan")


class Lane:
    """One problem at a time: ours in a worker process (killed at the timeout), the peer's in another."""

    def __init__(self, context: Any, peer: Peer, threads: int | None = None) -> None:
        self.context, self.peer, self.threads = context, peer, threads
        self.ours, self.theirs = self._pool(), self._pool()

    def _pool(self) -> ProcessPoolExecutor:
        return ProcessPoolExecutor(1, mp_context=self.context)

    def run(self, path: Path, timeout_s: float, time_limit_s: float) -> dict[str, Any]:
        """Both planners on the scene file ``path``, warm: the row's ``ours_*`` and peer's values."""
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
        try:
            self.theirs.submit(self.peer.warm, str(path)).result()
            found = self.theirs.submit(self.peer.run, str(path), timeout_s).result()
        except Exception as exc:  # the peer cannot take this robot or scene: unsolved, and why; ours stands
            found = {
                "ok": False,
                "time_s": float("nan"),
                "why": one_line(f"{type(exc).__name__}: {exc}", 200),
            }
            if isinstance(exc, BrokenProcessPool):  # its process died: a new one for the next problem
                self.theirs = self._pool()
        row |= {f"{self.peer.name}_{k}": v for k, v in found.items()}
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


def table(rows: list[dict[str, Any]], peer: Peer) -> list[str]:
    """The markdown table of ``rows`` per robot and class (module docstring); each row printed too."""
    name, label = peer.name, peer.label
    print(f"\n{'robot':6s} {'class':17s} {'valid':>5s} {'ours':>4s} {name[:8]:>8s}", end="")
    print(f"  {'ours med/p95 s':>15s}  {'peer med/p95 s':>15s}  ratio  both   all  dur/bound", end="")
    print("  peer dur/bound  jerk/lim  >effort  checked  peer failing (touching)")
    lines = [
        f"| robot | class | valid | solved ours | solved {label} | ours median (p95) [s] "
        f"| {label} median (p95) [s] | ratio | ratio, both solved | ratio, all "
        f"| ours duration / Ruckig bound | {label} duration / Ruckig bound | {label} jerk / limit "
        f"| {label} beyond an effort limit | ours passing `check` "
        f"| {label} paths failing `check` (touching) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for robot_name in dict.fromkeys(r["robot"] for r in rows):
        for problem_class in [*dict.fromkeys(r["class"] for r in rows if r["robot"] == robot_name), "all"]:
            group = [r for r in rows if r["robot"] == robot_name and problem_class in ("all", r["class"])]
            group = [r for r in group if not r["invalid"]]
            if not group:
                continue
            solved = [r for r in group if r.get(f"{name}_ok")]
            mine = [r["ours_time_s"] for r in group if r.get("ours_ok")]
            theirs_s = [r[f"{name}_time_s"] for r in solved]
            bounds = [r["ours_over_bound"] for r in group if r.get("ours_ok")]
            peer_bounds = [r[f"{name}_over_bound"] for r in solved if f"{name}_over_bound" in r]
            jerks = [r[f"{name}_jerk"] for r in solved]
            ratio = median_ratio(mine, theirs_s)
            both = [r for r in group if r.get("ours_ok") and r.get(f"{name}_ok")]
            ratio_both = median_ratio([r["ours_time_s"] for r in both], [r[f"{name}_time_s"] for r in both])
            timed = [r for r in group if np.isfinite(r[f"{name}_time_s"])]  # not those it could not load
            ratio_all = median_ratio([r["ours_time_s"] for r in timed], [r[f"{name}_time_s"] for r in timed])
            checked = sum(1 for r in group if r.get("ours_checked"))
            beyond = sum(1 for r in solved if r[f"{name}_torque"] > 1.0 + 1e-9)
            failing = sum(1 for r in solved if not r.get(f"{name}_checked", True))  # OMPL's: verified
            touching = sum(1 for r in solved if not r.get(f"{name}_clear", True))
            print(
                f"{robot_name:6s} {problem_class:17s} {len(group):5d} {len(mine):4d} {len(solved):8d}  "
                f"{percentile(mine, 50):6.2f} / {percentile(mine, 95):6.2f}  "
                f"{percentile(theirs_s, 50):6.2f} / {percentile(theirs_s, 95):6.2f}"
                f"  {ratio:5.2f} {ratio_both:5.2f} {ratio_all:5.2f}  {percentile(bounds, 50):9.3f}"
                f"  {percentile(peer_bounds, 50):14.3f}  {percentile(jerks, 50):8.1f}"
                f"  {beyond:7d}  {checked:7d}"
                f"  {failing:12d} ({touching})"
            )
            lines.append(
                f"| {robot_name} | {problem_class} | {len(group)} | {len(mine)} | {len(solved)} "
                f"| {percentile(mine, 50):.3f} ({percentile(mine, 95):.3f}) "
                f"| {percentile(theirs_s, 50):.3f} ({percentile(theirs_s, 95):.3f}) | {ratio:.2f} "
                f"| {ratio_both:.2f} ({len(both)}) | {ratio_all:.2f} | {percentile(bounds, 50):.3f} "
                f"| {percentile(peer_bounds, 50):.3f} | {percentile(jerks, 50):.1f} | {beyond} | {checked} "
                f"| {failing} ({touching}) |"
            )
    return lines


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
    parser.add_argument(
        "--peer",
        choices=sorted(PEERS),
        default="ompl",
        help="the peer: OMPL's RRT-Connect through Python callbacks, or roboplan's, compiled",
    )
    parser.add_argument("--out", type=Path, default=Path("out/bench_mbm"))
    args = parser.parse_args()
    peer = PEERS[args.peer]
    check_selection(parser, args)
    if args.time_limit is not None and not 0 < args.time_limit <= args.timeout:
        parser.error(f"--time-limit {args.time_limit:g} s must be in (0, --timeout = {args.timeout:g}] s")
    time_limit_s = args.time_limit or TIME_LIMIT_SHARE * args.timeout
    try:  # every scene and robot loaded before anything runs: a bad file is one line
        chosen = list(selected_cases(args, args.out))
        rows: list[dict[str, Any]] = [
            {"robot": c.robot, "class": c.group, "problem": c.number, "invalid": valid(c.path) or ""}
            for c in chosen
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
        lanes.put(Lane(context, peer, threads))
    finished = itertools.count(1)

    def solve(number: int) -> None:
        row, path = rows[number], chosen[number].path
        if not row["invalid"]:
            lane = lanes.get()
            try:
                row |= lane.run(path, args.timeout, time_limit_s)
            finally:
                lanes.put(lane)
        mark = "-" if row["invalid"] else summary(row, peer.name)
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
    drawn = f" drawn with seed {args.sample_seed}" if args.sample_seed is not None and not args.scenes else ""
    title = (
        f"{'Scene files' if args.scenes else f'MotionBenchMaker, {args.limit or 100} problem(s) per class'}"
        f"{drawn}, timeout {args.timeout:g} s (ours: time_limit_s {time_limit_s:g} s), "
        "warm (`scripts/bench_mbm.py`)"
    )
    report = [title, "", *table(rows, peer)]
    (args.out / "mbm.md").write_text("\n".join(report) + "\n")
    print(f"\nrows: {args.out / 'mbm.csv'}; table: {args.out / 'mbm.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
