"""Compile the kernels ahead of time: ``python -m planning.ahead_of_time [--robot URDF [--srdf SRDF]]``.

Every later process then runs them without importing numba (:mod:`cpr_kin.common.ahead`):
``cpr-plan plan`` starts about half a second sooner (docs/benchmarks.md). The kernels are
compiled with the argument types a warm-up calls them with (:func:`planning.warming.warm_up`,
on the bundled CPR and on each robot given), by numba's ``pycc`` and the machine's C compiler,
into the first writable folder of :func:`~cpr_kin.common.kernel_files.kernel_folders`. A
kernel the warm-up does not call, calls with types ``pycc`` cannot take, or ``pycc`` cannot
compile, stays numba's, compiled just in time as before. Run it again after an update: a
module built for other kernel files is not used.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cpr_kin.common.ahead import MODE_VARIABLE, Kernels, load_kernels, write_codes
from cpr_kin.common.kernel_files import (
    SUFFIX,
    export_name,
    guards_file,
    host_key,
    kernel_folders,
    kernel_key,
    module_name,
    part_name,
)
from cpr_kin.common.kernel_sources import sources_digest
from planning.kernel_build import Export, build_parts


def argument_spec(numba_type: Any) -> list[Any] | None:
    """The :class:`~cpr_kin.common.ahead.Kernels` spec of a numba argument type (``None``: none)."""
    from numba.core import types

    if isinstance(numba_type, types.Array):
        if not numba_type.aligned or not isinstance(numba_type.dtype, types.Number | types.Boolean):
            return None
        return ["array", str(numba_type.dtype), numba_type.ndim, numba_type.layout, not numba_type.mutable]
    if numba_type == types.float64:
        return ["float"]
    if numba_type == types.int64:
        return ["int"]
    if numba_type == types.boolean:
        return ["bool"]
    if isinstance(numba_type, types.BaseTuple):
        items = [argument_spec(item) for item in numba_type.types]  # type: ignore[attr-defined]
        return None if any(item is None for item in items) else ["tuple", items]
    return None


@dataclass(frozen=True)
class Build:
    """What a build compiled.

    Attributes:
        module: the path of its first extension module.
        parts: its extension modules, the first and the others beside it.
        compiled: the kernels compiled into them, ``module:name`` each.
        uncalled: kernels the warm-up never called from Python: left to numba, if ever so called.
        uncompilable: kernels ``pycc`` could not compile: left to numba.
    """

    module: Path
    parts: int
    compiled: tuple[str, ...]
    uncalled: tuple[str, ...]
    uncompilable: tuple[str, ...]


def compile_kernels(folder: Path, warm: Callable[[], object]) -> Build:
    """Run ``warm``, then compile every kernel it called into ``folder``.

    The process must compile just in time (:data:`~cpr_kin.common.ahead.MODE_VARIABLE` ``jit``).
    The module, its signatures and its guards' code (:meth:`~cpr_kin.common.ahead.Kernels.guard_codes`)
    are written under a temporary name and renamed into place.
    """
    from numba.pycc import CC  # type: ignore[attr-defined]

    from cpr_kin.common import compiled

    warm()
    name = module_name(sources_digest())
    signatures: dict[str, list[list[Any]]] = {}
    exports: list[Export] = []
    uncalled = []
    for function in list(compiled._KERNELS):
        dispatcher: Any = compiled._dispatcher(function)
        key = kernel_key(function)
        exported: list[list[Any]] = []
        for arguments in dispatcher.signatures:
            specs = [argument_spec(t) for t in arguments]
            if any(spec is None for spec in specs):
                continue
            export = export_name(function.__module__, function.__name__, len(exported))
            exports.append(Export(key, export, dispatcher.overloads[arguments].signature, function))
            exported.append(specs)
        if exported:
            signatures[key] = exported
        elif not compiled._KERNELS[function]:
            uncalled.append(key)
    folder.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=folder) as scratch:
        failed, parts = build_parts(name, exports, Path(scratch), CC, parts=cores())
        signatures = {key: specs for key, specs in signatures.items() if key not in failed}
        for stale in folder.glob(f"{name}_part*"):  # an earlier build's parts: all of them replaced
            stale.unlink(missing_ok=True)
        for part in reversed(range(parts)):  # the first part last: the build is whole once it is there
            os.replace(
                Path(scratch) / f"{part_name(name, part)}{SUFFIX}",
                folder / f"{part_name(name, part)}{SUFFIX}",
            )
        module = folder / f"{name}{SUFFIX}"
        (Path(scratch) / "signatures.json").write_text(json.dumps(signatures, indent=1))
        os.replace(Path(scratch) / "signatures.json", folder / f"{name}.json")
        codes = Kernels(None, signatures).guard_codes(compiled._KERNELS)  # compiled here, not in each process
        write_codes(Path(scratch) / "guards", codes)
        os.replace(Path(scratch) / "guards", folder / guards_file(name))
    for older in folder.glob(f"cpr_kernels_*_{host_key()}*"):  # other kernel files: never loaded again
        if not older.name.startswith(name):
            older.unlink(missing_ok=True)
    return Build(module, parts, tuple(signatures), tuple(uncalled), tuple(failed))


def cores() -> int:
    """The cores this process may run on, at most four: the build's parts, compiled at once."""
    usable = os.sched_getaffinity(0) if hasattr(os, "sched_getaffinity") else range(os.cpu_count() or 1)
    return max(1, min(4, len(usable)))


def default_robots() -> list[tuple[Path, Path | None]]:
    """The arms a build warms up on beside the CPR, where on this machine: ``(URDF, SRDF)`` each.

    They have pairs of their own to bound and exact meshes, which the CPR lacks:
    example-robot-data's Panda (the ``robots`` extra), and MotionBenchMaker's Panda and UR5 where
    ``planning.bench.mbm`` has unpacked their resources in the disk cache: the Panda's links come
    near enough for the near pairs' cells, the UR5's meshes decide points inside them.
    """
    from cpr_kin.common.disk_cache import cache_folder
    from cpr_kin.model.packages import example_robot_data_share

    robots: list[tuple[Path, Path | None]] = []
    share = example_robot_data_share()
    if share is not None:
        panda = share / "example-robot-data" / "robots" / "panda_description"
        robots.append((panda / "urdf" / "panda.urdf", panda / "srdf" / "panda.srdf"))
    for name in ("panda", "ur5"):
        for mbm in sorted(cache_folder().glob(f"vamp_planner-*/resources/{name}"))[-1:]:
            robots.append((mbm / f"{name}.urdf", mbm / f"{name}.srdf"))
    return [(urdf, srdf) for urdf, srdf in robots if urdf.is_file()]


def _warm_robots(urdfs: list[Path], srdfs: list[Path], bundled_only: bool) -> None:
    """The warm-up on the bundled CPR, then on each robot given, or on :func:`default_robots`.

    ``urdfs`` and ``srdfs`` are given in the robots' order; where none is given, the default
    robots are warmed on unless ``bundled_only``.
    """
    import cpr_kin as ck
    from planning.warming import warm_up

    warm_up()
    robots = [(urdf, srdfs[i] if i < len(srdfs) else None) for i, urdf in enumerate(urdfs)]
    if not robots and not bundled_only:
        robots = default_robots()
    for urdf, srdf in robots:
        warm_up(ck.load_robot(urdf, srdf=srdf))


def writable_folder() -> Path:
    """The first folder of :func:`~cpr_kin.common.kernel_files.kernel_folders` this process may write in."""
    for folder in kernel_folders():
        try:
            folder.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryFile(dir=folder):
                return folder
        except OSError:
            continue
    raise SystemExit(f"error: no folder to write the kernels in: {', '.join(map(str, kernel_folders()))}")


def main(argv: list[str] | None = None) -> int:
    """The command line: compile the kernels, say where and which."""
    parser = argparse.ArgumentParser(
        prog="python -m planning.ahead_of_time", description=__doc__.splitlines()[0]
    )
    parser.add_argument(
        "--robot", type=Path, action="append", default=[], help="a URDF to warm up on as well"
    )
    parser.add_argument(
        "--srdf", type=Path, action="append", default=[], help="its SRDF (in the robots' order)"
    )
    parser.add_argument(
        "--force", action="store_true", help="compile even where a module for today's sources exists"
    )
    parser.add_argument(
        "--bundled-only", action="store_true", help="warm up on the bundled CPR alone, not the default arms"
    )
    parser.add_argument(
        "--just-in-time",
        action="store_true",
        help="only run the warm-up, numba compiling into its disk cache (no C compiler needed)",
    )
    args = parser.parse_args(argv)
    if args.just_in_time:  # the kernels numba will load, not compile, in the processes that run it
        os.environ[MODE_VARIABLE] = "jit"
        started = time.perf_counter()
        _warm_robots(args.robot, args.srdf, args.bundled_only)
        print(f"the kernels are in numba's disk cache ({time.perf_counter() - started:.0f} s)")
        return 0
    if shutil.which(os.environ.get("CC", "cc")) is None and shutil.which("gcc") is None:
        print(
            "error: no C compiler (cc or gcc) on the PATH: the kernels stay compiled just in time",
            file=sys.stderr,
        )
        return 2
    if importlib.util.find_spec("setuptools") is None:
        print(
            "error: numba's pycc needs setuptools, which this environment lacks (Python 3.12's venvs come "
            "without it): pip install setuptools; until then the kernels stay compiled just in time",
            file=sys.stderr,
        )
        return 2
    built = load_kernels()
    if built is not None and built.path is not None and not args.force:
        print(f"the kernels compiled ahead of time are up to date: {built.path}")
        return 0
    os.environ[MODE_VARIABLE] = "jit"  # the warm-up must run numba's dispatchers, whose types are compiled

    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as cold:
        # numba compiles afresh, not from its disk cache: a kernel loaded from there does not
        # compile the kernels it calls, whose types then go unseen and unexported
        os.environ["NUMBA_CACHE_DIR"] = cold
        build = compile_kernels(
            writable_folder(), lambda: _warm_robots(args.robot, args.srdf, args.bundled_only)
        )
    seconds = time.perf_counter() - started
    beside = {1: "", 2: " and 1 part beside it"}.get(build.parts, f" and {build.parts - 1} parts beside it")
    print(
        f"{len(build.compiled)} kernels compiled ahead of time into {build.module}{beside} in {seconds:.0f} s"
    )
    if build.uncompilable:
        print(f"pycc could not compile these, left to numba: {', '.join(build.uncompilable)}")
    if build.uncalled:
        uncalled = ", ".join(build.uncalled)
        print(f"not called from Python by the warm-up, left to numba if ever so called: {uncalled}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
