"""The kernels' disk cache in a source checkout: dropped when a file that compiles a kernel changes;
the first compilation of a process said once."""

from __future__ import annotations

import importlib.util
import logging
import subprocess
import sys
import time
from pathlib import Path
from types import ModuleType

import numba
import numba.core.event
import pytest

from cpr_kin.common.compiled import COMPILING
from cpr_kin.common.just_in_time import CompileWatch
from cpr_kin.common.kernel_sources import forget_stale_kernels, sources_digest

PACKAGES = ("pkg",)


def checkout(root: Path) -> list[Path]:
    """A checkout of one package: a kernel's file, another file, and the kernel's cached code."""
    (root / ".git").mkdir(parents=True)
    package = root / "pkg"
    (package / "__pycache__").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "kernels.py").write_text(
        "from cpr_kin.common.compiled import njit\n\n\ndef f(x):\n    return x\n"
    )
    (package / "other.py").write_text("LIMIT = 1.0\n")
    return cached(package)


def cached(package: Path) -> list[Path]:
    files = [package / "__pycache__" / name for name in ("kernels.f-4.py311.nbi", "kernels.f-4.py311.1.nbc")]
    for path in files:
        path.write_bytes(b"compiled")
    return files


def test_a_kernels_file_changed_drops_the_cached_kernels(tmp_path: Path) -> None:
    stamp = tmp_path / "stamp.txt"
    files = checkout(tmp_path / "repo")
    package = tmp_path / "repo" / "pkg"
    assert forget_stale_kernels(tmp_path / "repo", stamp, PACKAGES)  # never seen: what is cached may be stale
    assert not any(path.exists() for path in files)
    files = cached(package)
    assert not forget_stale_kernels(tmp_path / "repo", stamp, PACKAGES)  # nothing changed
    (package / "other.py").write_text("LIMIT = 2.0\n")  # a file that compiles nothing
    assert not forget_stale_kernels(tmp_path / "repo", stamp, PACKAGES)
    assert all(path.exists() for path in files)
    (package / "kernels.py").write_text((package / "kernels.py").read_text().replace("return x", "return 2"))
    assert forget_stale_kernels(tmp_path / "repo", stamp, PACKAGES)
    assert not any(path.exists() for path in files)


def test_the_sources_digest_follows_the_kernel_files_alone(tmp_path: Path) -> None:
    checkout(tmp_path / "repo")
    package, stamp = tmp_path / "repo" / "pkg", tmp_path / "stamp.txt"
    first = sources_digest(tmp_path / "repo", stamp, PACKAGES)
    assert first == sources_digest(tmp_path / "repo", tmp_path / "another.txt", PACKAGES)  # from the bytes
    (package / "other.py").write_text("LIMIT = 2.0\n")
    assert sources_digest(tmp_path / "repo", stamp, PACKAGES) == first
    (package / "kernels.py").write_text((package / "kernels.py").read_text() + "\n# changed\n")
    assert sources_digest(tmp_path / "repo", stamp, PACKAGES) != first


def test_the_sources_digest_follows_the_warm_up_that_chooses_the_kernels(tmp_path: Path) -> None:
    """A warm-up that calls a kernel anew must name a module yet to be built, not an older one."""
    checkout(tmp_path / "repo")
    planning = tmp_path / "repo" / "planning"
    planning.mkdir()
    (planning / "__init__.py").write_text("")
    (planning / "warming.py").write_text("def warm_up():\n    pass\n")
    (planning / "other.py").write_text("LIMIT = 1.0\n")
    packages, stamp = ("pkg", "planning"), tmp_path / "stamp.txt"
    first = sources_digest(tmp_path / "repo", stamp, packages)
    (planning / "other.py").write_text("LIMIT = 2.0\n")
    assert sources_digest(tmp_path / "repo", stamp, packages) == first
    (planning / "warming.py").write_text("def warm_up():\n    f(1)\n")
    assert sources_digest(tmp_path / "repo", stamp, packages) != first


def test_outside_a_checkout_nothing_is_touched(tmp_path: Path) -> None:
    files = checkout(tmp_path / "repo")
    (tmp_path / "repo" / ".git").rmdir()
    assert not forget_stale_kernels(tmp_path / "repo", tmp_path / "stamp.txt", PACKAGES)
    assert all(path.exists() for path in files)


def test_a_stamp_that_cannot_be_kept_is_no_error(tmp_path: Path) -> None:
    files = checkout(tmp_path / "repo")
    (tmp_path / "blocker").write_text("a file where the stamp's folder would be")
    # nothing seen, as in a checkout never stamped: what is cached may be stale, and is dropped
    assert forget_stale_kernels(tmp_path / "repo", tmp_path / "blocker" / "stamp.txt", PACKAGES)
    assert not any(path.exists() for path in files)


def kernel_module(folder: Path, name: str) -> ModuleType:
    """A module of one cached kernel ``f`` in ``folder/kernel.py``, imported anew as ``name``."""
    source = folder / "kernel.py"
    if not source.exists():
        source.write_text("import numba\n\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1\n")
    spec = importlib.util.spec_from_file_location(name, source)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_first_compilation_is_said_once_and_a_cached_kernel_says_nothing(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    log = logging.getLogger("cpr_kin.test_compiled")
    listener = CompileWatch(log, COMPILING)
    with (
        caplog.at_level(logging.INFO, logger=log.name),
        numba.core.event.install_listener("numba:compile", listener),
    ):
        assert kernel_module(tmp_path, "loaded_from_source").f(1) == 2  # compiled, kept on disk
        assert [r.getMessage() for r in caplog.records] == [COMPILING]
        numba.njit(lambda x: x * 2)(3)  # a second compilation: said already
        assert len(caplog.records) == 1

    caplog.clear()
    again = CompileWatch(log, COMPILING)
    with (
        caplog.at_level(logging.INFO, logger=log.name),
        numba.core.event.install_listener("numba:compile", again),
    ):
        assert kernel_module(tmp_path, "loaded_from_cache").f(1) == 2  # the same file: numba's cache
        assert caplog.records == [] and not again.said
        numba.njit(lambda x: x * 3)(3)
        assert [r.getMessage() for r in caplog.records] == [COMPILING] and again.said


ONE_SPECIALISATION = """
import gc
import numba
import cpr_kin as ck
from planning.bench.mbm import vamp_resources
from planning.warming import warm_up

warm_up()
resources = vamp_resources("panda")
warm_up(ck.load_robot(resources / "panda.urdf", srdf=resources / "panda.srdf"))
for kernel in gc.get_objects():
    if isinstance(kernel, numba.core.registry.CPUDispatcher) and len(kernel.signatures) > 1:
        function = kernel.py_func
        if function.__module__.split(".")[0] in ("cpr_kin", "planning"):
            print(function.__module__, function.__qualname__, len(kernel.signatures))
"""


@pytest.mark.slow
def test_a_plan_loads_each_kernel_once() -> None:
    """Every kernel planning calls is called with one set of argument types (array layout, read-only
    or not): each further one is another compiled version to load from disk in every new process.

    Counted in a process that loads the kernels from numba's disk cache, as every process after
    the first does: one that compiles them also counts the versions of the kernels they call,
    which live inside their callers' cached code, not in a file of their own (a first run
    fills the cache).
    """
    for _ in range(2):
        command = [sys.executable, "-c", ONE_SPECIALISATION]
        completed = subprocess.run(command, capture_output=True, text=True, check=False, timeout=600)
        assert completed.returncode == 0, completed.stderr
    assert completed.stdout == ""


def test_the_watch_times_compilations_the_outermost_once_and_not_a_cached_kernel(tmp_path: Path) -> None:
    numba.njit(lambda x: x - 1)(1)  # numba's own start (LLVM's), outside any compilation, done
    watch = CompileWatch(logging.getLogger("cpr_kin.test_compiled"), COMPILING)
    with numba.core.event.install_listener("numba:compile", watch):
        began = time.perf_counter()
        assert kernel_module(tmp_path, "timed_from_source").f(1) == 2  # compiled
        wall_s = time.perf_counter() - began
        assert 0.5 * wall_s < watch.seconds <= wall_s  # the call is mostly its compilation
        first_s = watch.seconds
        inner = numba.njit(lambda x: x + 1)
        outer = numba.njit(lambda x: inner(x) * 2)  # compiles inner within it
        began = time.perf_counter()
        assert outer(1) == 4
        wall_s = time.perf_counter() - began
        assert 0.5 * wall_s < watch.seconds - first_s <= wall_s  # nested, so counted once
    cached = CompileWatch(logging.getLogger("cpr_kin.test_compiled"), COMPILING)
    with numba.core.event.install_listener("numba:compile", cached):
        assert kernel_module(tmp_path, "timed_from_cache").f(1) == 2
    assert cached.seconds == 0.0


def test_the_end_of_a_compilation_begun_before_the_watch_adds_nothing() -> None:
    watch = CompileWatch(logging.getLogger("cpr_kin.test_compiled"), COMPILING)
    watch.on_end(None)  # registered while numba was compiling: its end alone arrives
    assert watch.seconds == 0.0
