"""Which MotionBenchMaker problems a script runs: ``--robots``, ``--classes``, ``--limit``, ``--names``.

``--sample-seed`` draws the ``--limit`` at random; ``--names`` keeps only the problems named;
:func:`selected_cases` gives them, or a script's ``--scenes`` files, as scene files.

``scripts/bench_mbm.py`` and ``scripts/import_mbm.py`` take the same selection::

    add_selection(parser)
    args = parser.parse_args()
    check_selection(parser, args)  # argparse's one line and exit 2 for a bad combination
    for problem in selected_problems(args, "panda"): ...
"""

from __future__ import annotations

import argparse
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from planning.batch import scene_files
from planning.bench.mbm import CLASSES, ROBOTS, Problem, import_problem, problems
from planning.cli.arguments import COUNT, SEED

PER_CLASS = 100
"""Problems in each MotionBenchMaker class: the largest ``--limit``."""


def add_selection(parser: argparse.ArgumentParser) -> None:
    """Add ``--robots`` (default: panda, ur5), ``--classes``, ``--limit``, ``--sample-seed``, ``--names``."""
    parser.add_argument("--robots", nargs="+", default=["panda", "ur5"], choices=list(ROBOTS))
    parser.add_argument("--classes", nargs="+", default=list(CLASSES), choices=list(CLASSES))
    parser.add_argument("--limit", type=COUNT, help=f"problems per class (default: all {PER_CLASS})")
    parser.add_argument(
        "--sample-seed",
        type=SEED,
        help="draw --limit problems of each class at random with this seed (default: the first --limit)",
    )
    parser.add_argument("--names", nargs="+", help="only these problems, e.g. box_0020 table_pick_0061")


def check_selection(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    """Refuse (``parser.error``) a ``--limit`` above :data:`PER_CLASS`, a sample seed without a limit."""
    check_limit(parser, args.limit)
    if args.sample_seed is not None and args.limit is None:
        parser.error(f"--sample-seed {args.sample_seed} goes with --limit (the sample's size per class)")
    for name in args.names or ():
        kind, _, number = name.rpartition("_")
        if kind not in CLASSES or not number.isdigit() or not 1 <= int(number) <= PER_CLASS:
            parser.error(
                f"--names {name}: a problem is <class>_<number 1-{PER_CLASS}>, class one of {list(CLASSES)}"
            )


def check_limit(parser: argparse.ArgumentParser, limit: int | None) -> None:
    """Refuse (``parser.error``) a ``--limit`` above :data:`PER_CLASS` (``None``: all of them)."""
    if limit is not None and limit > PER_CLASS:
        parser.error(f"--limit {limit} must be in [1, {PER_CLASS}] problems per class")


def selected_problems(args: argparse.Namespace, robot: str) -> Iterator[Problem]:
    """``robot``'s problems of the selection in ``args`` (:func:`planning.bench.mbm.problems`)."""
    chosen = problems(robot, tuple(args.classes), args.limit, args.sample_seed)
    return (p for p in chosen if p.name in args.names) if getattr(args, "names", None) else chosen


@dataclass(frozen=True)
class Case:
    """One problem a benchmark runs, as a scene file.

    Attributes:
        robot: the robot's name (MotionBenchMaker's), or the scene file's folder.
        group: the problem's class, or the file's name without a trailing ``_<number>``.
        number: its number in the class (0 for a file named without one).
        path: the scene file.
    """

    robot: str
    group: str
    number: int
    path: Path


def selected_cases(args: argparse.Namespace, out: Path) -> Iterator[Case]:
    """The cases of a script's arguments: ``args.scenes``' files, else the selection's problems.

    ``args.scenes``: scene files and folders (a folder: its ``*.yaml`` files by name); without
    them, each selected MotionBenchMaker problem of ``args.robots`` is imported into
    ``out/scenes/<robot>/<name>.yaml`` (:func:`planning.bench.mbm.import_problem`).
    """
    if getattr(args, "scenes", None):
        for given in args.scenes:
            for path in scene_files(given) if given.is_dir() else [given]:
                group, _, number = path.stem.rpartition("_")
                if not (group and number.isdigit()):
                    group, number = path.stem, "0"
                yield Case(path.resolve().parent.name, group, int(number), path)
        return
    for robot_name in args.robots:
        for problem in selected_problems(args, robot_name):
            path = out / "scenes" / robot_name / f"{problem.name}.yaml"
            import_problem(problem, path)
            yield Case(robot_name, problem.problem_class, problem.index, path)
