"""The kernels compiled ahead of time: the guards' choice of export or numba, the specs of numba's
types, the module found by its sources' digest, and a real build whose plans are numba's to the byte."""

from __future__ import annotations

import collections
import importlib.util
import json
import marshal
import os
import shutil
import subprocess
import sys
from pathlib import Path
from types import CodeType, SimpleNamespace
from typing import Any, ClassVar

import numpy as np
import pytest
from numba.core import types

from cpr_kin.common import ahead
from cpr_kin.common.ahead import MODE_VARIABLE, Kernels, kept_codes, kernels_in, load_kernels, write_codes
from cpr_kin.common.kernel_files import FOLDER_VARIABLE, SUFFIX, export_name, module_name
from cpr_kin.common.kernel_sources import sources_digest
from planning.ahead_of_time import argument_spec, cores
from planning.kernel_build import Export, build_module, build_parts, split_by_kernel

ROOT = Path(__file__).resolve().parents[1]
BUILT_VARIABLE = "CPR_TEST_BUNDLED_KERNELS"
"""A folder holding ``python -m planning.ahead_of_time --bundled-only``'s build of today's sources
(in CI, the one ``make wheel-check`` compiled in the wheel's venv): the test of a real build takes
its files instead of compiling the same kernels a second time; they must be of today's sources."""
F8_C = ["array", "float64", 2, "C", False]
"""A writable C-contiguous 2-d float64 array's spec."""


def kernel(values: Any, scale: Any, flags: Any = True) -> str:
    """The kernel's Python code: here, what ran."""
    return "python"


def guarded(specs: list[list[Any]]) -> tuple[Any, list[str]]:
    """``kernel`` behind a guard whose one export (a Python stand-in) takes ``specs``; the fallbacks asked."""
    asked: list[str] = []

    def fallback() -> Any:
        asked.append("numba")
        return kernel

    module = SimpleNamespace(**{export_name(__name__, "kernel", 0): lambda *args: "export"})
    kernels = Kernels(module, {f"{__name__}:kernel": [specs]})
    return kernels.guarded(kernel, fallback), asked


def test_a_guard_runs_the_export_where_numba_would_type_the_arguments_alike() -> None:
    guard, asked = guarded([F8_C, ["float"], ["tuple", [["int"], ["bool"]]]])
    good = np.ones((3, 2))
    assert guard(good, 0.5, (1, True)) == "export"
    assert guard(good, np.float64(0.5), (np.int64(1), np.bool_(False))) == "export"
    numba_returned = np.frombuffer(good.tobytes()).reshape(3, 2).copy()  # equal dtype, maybe another object
    assert guard(numba_returned, 0.5, (1, True)) == "export"
    assert guard.__name__ == "kernel" and guard.__wrapped__ is kernel and asked == []


@pytest.mark.parametrize(
    ("values", "scale", "flags"),
    [
        (np.ones((3, 2), dtype=np.float32), 0.5, (1, True)),  # another dtype
        (np.ones(3), 0.5, (1, True)),  # another number of dimensions
        (np.ones((2, 3)).T, 0.5, (1, True)),  # not C-contiguous
        (np.ones((3, 2)).astype(">f8"), 0.5, (1, True)),  # another byte order
        ([[1.0, 2.0]], 0.5, (1, True)),  # not an array
        (np.ones((3, 2)), 1, (1, True)),  # an int for a float
        (np.ones((3, 2)), 0.5, (1.0, True)),  # a float for an int
        (np.ones((3, 2)), 0.5, (1,)),  # a shorter tuple
        (np.ones((3, 2)), 0.5, (1, 1)),  # an int for a bool
    ],
)
def test_a_guard_falls_back_to_numba_where_the_types_differ(values: Any, scale: Any, flags: Any) -> None:
    guard, asked = guarded([F8_C, ["float"], ["tuple", [["int"], ["bool"]]]])
    assert guard(values, scale, flags) == "python"
    assert guard(values, scale, flags) == "python" and asked == ["numba"]  # asked once


def test_a_read_only_array_takes_only_a_read_only_export_and_keywords_are_the_kernels() -> None:
    guard, _ = guarded([F8_C, ["float"], ["bool"]])
    frozen = np.ones((3, 2))
    frozen.setflags(write=False)
    assert guard(frozen, 0.5, True) == "python"  # numba would compile a read-only version
    reading, _ = guarded([["array", "float64", 2, "C", True], ["float"], ["bool"]])
    assert reading(frozen, 0.5, True) == "export" and reading(np.ones((3, 2)), 0.5, True) == "export"
    assert reading(frozen, scale=0.5, flags=True) == "export"
    assert reading(frozen, flags=True, scale=1) == "python"  # an int for the float, by its name


def test_an_array_that_passed_is_not_checked_again_but_another_is() -> None:
    guard, _ = guarded([F8_C, ["float"], ["bool"]])
    fixed = np.ones((3, 2))
    assert guard(fixed, 0.5, True) == "export"
    assert guard(fixed, 0.5, True) == "export"
    assert guard(np.ones((3, 2), dtype=np.int64), 0.5, True) == "python"
    assert guard(fixed, 0.5, True) == "export"


def test_a_default_argument_is_the_kernels() -> None:
    guard, _ = guarded([F8_C, ["float"], ["bool"]])
    assert guard(np.ones((3, 2)), 0.5) == "export"
    guard, _ = guarded([F8_C, ["float"], ["int"]])
    assert guard(np.ones((3, 2)), 0.5) == "python"  # the default, True, is no int


def test_a_kernel_without_an_export_always_falls_back() -> None:
    kernels = Kernels(SimpleNamespace(), {})
    assert kernels.guarded(kernel, lambda: kernel)(np.ones((3, 2)), 0.5, True) == "python"


def variadic(*values: Any) -> str:
    """No kernel: its parameters are not a kernel's."""
    return "python"


def nested_codes(code: CodeType) -> list[CodeType]:
    """``code`` and every code object compiled inside it (compare them by identity: equal code is ``==``)."""
    inner = [c for c in code.co_consts if isinstance(c, CodeType)]
    return [code, *(n for c in inner for n in nested_codes(c))]


def test_a_guard_runs_the_code_the_build_kept_where_its_source_is_the_same(tmp_path: Path) -> None:
    specs = {f"{__name__}:kernel": [[F8_C, ["float"], ["bool"]]]}
    module = SimpleNamespace(**{export_name(__name__, "kernel", 0): lambda *args: "export"})
    codes = Kernels(None, specs).guard_codes([kernel, variadic])  # variadic: no kernel's parameters
    key = f"{__name__}:kernel"
    assert list(codes) == [key]
    source = codes[key][0]
    write_codes(tmp_path / "guards", codes)
    kept = kept_codes(tmp_path / "guards")
    assert kept.keys() == codes.keys() and kept[key][0] == source

    guard = Kernels(module, specs, kept).guarded(kernel, lambda: kernel)
    assert any(c is guard.__code__ for c in nested_codes(kept[key][1]))  # the kept code, not compiled again
    assert guard(np.ones((3, 2)), 0.5, True) == "export" and guard(np.ones(3), 0.5, True) == "python"
    stale = {key: ("def _make(): pass", kept[key][1])}  # kept for another source: compiled afresh
    guard = Kernels(module, specs, stale).guarded(kernel, lambda: kernel)
    assert not any(c is guard.__code__ for c in nested_codes(kept[key][1]))
    assert guard(np.ones((3, 2)), 0.5, True) == "export"


@pytest.mark.parametrize(
    "content",
    [
        b"",
        b"not marshal",
        marshal.dumps([1, 2]),
        marshal.dumps((importlib.util.MAGIC_NUMBER, {"k": (1, 2)})),
        marshal.dumps(
            (b"other", {"k": ("def _make(): pass", compile("pass", "k", "exec"))})
        ),  # another Python's
    ],
)
def test_guards_code_that_cannot_be_read_is_none_kept(tmp_path: Path, content: bytes) -> None:
    (tmp_path / "guards").write_bytes(content)
    assert kept_codes(tmp_path / "guards") == {}
    assert kept_codes(tmp_path / "missing") == {}


Chain = collections.namedtuple("Chain", "parent axis")


def test_numba_types_become_specs_and_the_others_none() -> None:
    array = types.Array(types.float64, 2, "C")
    frozen = types.Array(types.int64, 1, "A", readonly=True)
    assert argument_spec(array) == ["array", "float64", 2, "C", False]
    assert argument_spec(frozen) == ["array", "int64", 1, "A", True]
    assert argument_spec(types.float64) == ["float"]
    assert argument_spec(types.int64) == ["int"]
    assert argument_spec(types.boolean) == ["bool"]
    tuple_of: Any = types.UniTuple  # numba's types are untyped for mypy
    named = types.NamedTuple([array, frozen], Chain)  # type: ignore[no-untyped-call]
    assert argument_spec(named) == ["tuple", [argument_spec(array), argument_spec(frozen)]]
    assert argument_spec(tuple_of(types.float64, 2)) == ["tuple", [["float"], ["float"]]]
    for unsupported in (types.float32, types.unicode_type, tuple_of(types.float32, 2)):
        assert argument_spec(unsupported) is None


def test_no_module_where_none_was_built_or_the_mode_is_jit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv(MODE_VARIABLE, "ahead")
    assert load_kernels([tmp_path]) is None  # an empty folder
    (tmp_path / "cpr_kernels_0000.json").write_text("{}")  # another digest's
    assert load_kernels([tmp_path]) is None
    monkeypatch.setenv(MODE_VARIABLE, "jit")
    assert load_kernels() is None


PLAN = """
import hashlib, sys
import numpy as np
import planning
result = planning.plan(planning.paper_scene(seed=3))
from cpr_kin.bounds.bound_kernels import groups_below
print(type(groups_below).__name__, "numba" in sys.modules)
samples = result.trajectory(np.linspace(0.0, result.trajectory.duration, 101))
print(hashlib.sha256(result.waypoints.tobytes() + samples.tobytes()).hexdigest(),
      result.verification.certified_min_m.hex())
"""

NEAR_LINKS = """
import sys
import numpy as np
import cpr_kin as ck
from planning.bench.mbm import vamp_resources
resources = vamp_resources("panda")
robot = ck.load_robot(resources / "panda.urdf", srdf=resources / "panda.srdf")
q = ck.sampled_configurations(robot.model, 64, np.random.default_rng(0))
ck.CollisionWorld(robot, []).self_collision.violated(q, 0.0)
from cpr_kin.collision.self_split import _SCREENS
near = any(screen.near_cells.grids is not None for screen in _SCREENS[robot].values())
print(f"near pairs: {near}, numba: {'numba' in sys.modules}")
"""


def run(arguments: list[str], environment: dict[str, str]) -> list[str]:
    """The lines ``python ARGUMENTS`` prints in a new process with ``environment`` set."""
    completed = subprocess.run(
        [sys.executable, *arguments],
        capture_output=True,
        text=True,
        check=False,
        timeout=900,
        cwd=ROOT,
        env={**os.environ, **environment},
    )
    assert completed.returncode == 0, completed.stderr
    return completed.stdout.split("\n")


DESCENT = """
import sys
import numpy as np
import cpr_kin as ck
from cpr_kin.kinematics import ik_descent
from cpr_kin.kinematics.tool_chain import ToolChain
from planning.curves import horner
robot = ck.load_cpr()
chain, tool = ToolChain.of(robot).arrays
goal = (np.array([0.4, 0.3, 0.3]), np.eye(3), np.array([1e-4, 1e-3]), False)
step = (np.ones(robot.nq), robot.limits.lower.copy(), robot.limits.upper.copy(), np.array([1e-3, 0.3, 0.05]))
q = (robot.limits.lower + robot.limits.upper) / 2
exported = ik_descent.descend(q, chain, tool, goal, step, (150, 20))
print("numba:", "numba" in sys.modules)
fallen = ik_descent.descend(q.astype(np.float32), chain, tool, goal, step, (150, 20))
print("numba:", "numba" in sys.modules)
print(f"descend: {type(ik_descent.descend).__name__}, evaluate: {type(horner.evaluate).__name__}")
if hasattr(horner.evaluate, "__wrapped__"):
    import cpr_kin.common.compiled as compiled
    before = set(compiled._ALONE)
    horner.evaluate(np.ones((1, 2, 8)), np.array([0.0, 1.0]), np.array([0.5]))
    print("horner after the fallback:", "its export" if set(compiled._ALONE) == before else "numba")
else:
    print("horner after the fallback: numba")
print(exported[1], exported[0].tobytes().hex())
print(fallen[1], np.asarray(fallen[0], dtype=float).tobytes().hex())
"""


@pytest.mark.slow
def test_kernels_compiled_ahead_plan_the_bits_numba_plans_without_numba(tmp_path: Path) -> None:
    ahead = {FOLDER_VARIABLE: str(tmp_path), MODE_VARIABLE: "ahead"}
    if os.environ.get(BUILT_VARIABLE):
        built_in, name = Path(os.environ[BUILT_VARIABLE]), module_name(sources_digest())
        assert (built_in / f"{name}{SUFFIX}").is_file(), f"{built_in} holds no build of today's sources"
        for file in built_in.glob(f"{name}*"):  # its parts too
            shutil.copy2(file, tmp_path)
    else:
        built = run(["-m", "planning.ahead_of_time", "--bundled-only"], ahead)
        assert "kernels compiled ahead of time into" in built[0]
    assert run(["-m", "planning.ahead_of_time", "--bundled-only"], ahead)[0].startswith(
        "the kernels compiled ahead of time are up to date"
    )
    assert len(list(tmp_path.glob("cpr_kernels_*.so"))) == cores()  # one part per core, at most four
    (signatures_file,) = tmp_path.glob("cpr_kernels_*.json")
    signatures = json.loads(signatures_file.read_text())
    assert "cpr_kin.bounds.bound_kernels:groups_below" in signatures
    (guards,) = tmp_path.glob("cpr_kernels_*.guards")  # their code, compiled by the build
    assert signatures.keys() <= kept_codes(guards).keys()

    just_in_time = run(["-c", PLAN], {FOLDER_VARIABLE: str(tmp_path), MODE_VARIABLE: "jit"})
    compiled_ahead = run(["-c", PLAN], ahead)
    assert just_in_time[0] == "CPUDispatcher True"
    assert compiled_ahead[0] == "function False"  # the guard; numba never imported
    assert compiled_ahead[1] == just_in_time[1]  # the same trajectory, to the bit

    # an arm whose links come near each other at most configurations (the MotionBenchMaker Panda's):
    # its self check looks them up in the near pairs' grids, a kernel the CPR's plans never call;
    # a build on the CPR alone exports it too, or that arm's every process would run numba
    assert run(["-c", NEAR_LINKS], ahead)[0] == "near pairs: True, numba: False"

    # argument types no export takes: numba compiles the kernel then, and computes what it would
    mixed = """
import sys
import numpy as np
from planning.curves.horner import evaluate
coefficients = np.arange(24.0).reshape(2, 3, 4) / 7
values = evaluate(coefficients, np.array([0.0, 1.0, 2.0]), np.linspace(0.0, 2.0, 5))
print("numba" in sys.modules, values.tobytes().hex())
values = evaluate(coefficients.astype(np.float32), np.array([0.0, 1.0, 2.0]), np.linspace(0.0, 2.0, 5))
print("numba" in sys.modules, values.tobytes().hex())
"""
    exported, fallen_back = run(["-c", mixed], ahead)[:2]
    reference = run(["-c", mixed], {MODE_VARIABLE: "jit"})
    assert exported.startswith("False ") and fallen_back.startswith("True ")
    assert [exported.split()[1], fallen_back.split()[1]] == [line.split()[1] for line in reference[:2]]

    # a kernel that calls kernels (the IK's descent: the tool's placement, Jacobian, least squares)
    # falls back alone: numba compiles it and those it calls, and every other kernel keeps its export
    alone = run(["-c", DESCENT], ahead)
    assert alone[:2] == ["numba: False", "numba: True"]
    assert alone[2] == "descend: function, evaluate: function"  # guards, not numba's dispatchers
    assert alone[3] == "horner after the fallback: its export"
    assert alone[4:6] == run(["-c", DESCENT], {MODE_VARIABLE: "jit"})[4:6]  # the same answers


def test_the_build_says_what_it_lacks_and_leaves_the_kernels_to_numba(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import importlib.util
    import shutil

    from planning import ahead_of_time

    finds = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name: None if name == "setuptools" else finds(name)
    )
    assert ahead_of_time.main([]) == 2
    assert "numba's pycc needs setuptools" in capsys.readouterr().err
    monkeypatch.setattr(shutil, "which", lambda name: None)
    assert ahead_of_time.main([]) == 2
    assert "no C compiler (cc or gcc) on the PATH" in capsys.readouterr().err


class FakeCompiler:
    """numba's ``pycc.CC`` as the build uses it: it fails a module holding an export named ``*bad*``."""

    modules: ClassVar[list[list[str]]] = []

    def __init__(self, name: str) -> None:
        self.name, self.output_dir, self.target_cpu = name, "", ""
        self.exports: list[str] = []

    def export(self, name: str, signature: Any) -> Any:
        return lambda function: self.exports.append(name)

    def compile(self) -> None:
        FakeCompiler.modules.append(list(self.exports))
        if any("bad" in name for name in self.exports):
            raise TypeError("No conversion from Literal[int](1) to Literal[int](0)")
        (Path(self.output_dir) / f"{self.name}.so").write_text(" ".join(self.exports))


def test_a_build_leaves_out_the_kernels_pycc_cannot_compile_and_compiles_the_rest(tmp_path: Path) -> None:
    exports = [
        Export(f"m:{k}", f"m__{k}__{i}", None, kernel)
        for k, i in [("good", 0), ("bad", 0), ("good", 1), ("also", 0)]
    ]
    FakeCompiler.modules = []
    assert build_module("cpr_kernels_x", exports, tmp_path, FakeCompiler) == ["m:bad"]
    assert (tmp_path / "cpr_kernels_x.so").read_text() == "m__good__0 m__good__1 m__also__0"
    # all together, then each kernel alone, then the module without the one that failed
    assert FakeCompiler.modules == [
        [e.name for e in exports],
        ["m__good__0", "m__good__1"],
        ["m__bad__0"],
        ["m__also__0"],
        ["m__good__0", "m__good__1", "m__also__0"],
    ]
    FakeCompiler.modules = []
    good = [e for e in exports if e.key != "m:bad"]
    assert build_module("cpr_kernels_y", good, tmp_path, FakeCompiler) == []
    assert len(FakeCompiler.modules) == 1  # compiled once where all compile


def test_the_exports_are_dealt_into_parts_each_kernel_whole() -> None:
    exports = [Export(f"m:k{k}", f"m__k{k}__{i}", None, kernel) for k in range(5) for i in range(k % 3 + 1)]
    for parts in (1, 2, 3, 4, 7):
        split = split_by_kernel(exports, parts)
        assert len(split) == min(parts, 5) and all(split)  # no empty part
        assert sorted(e.name for part in split for e in part) == sorted(e.name for e in exports)
        kernels = [{e.key for e in part} for part in split]
        assert sum(map(len, kernels)) == 5  # a kernel's signatures in one part
        assert max(map(len, kernels)) - min(map(len, kernels)) <= 1


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the parts are compiled at once on Linux")
def test_a_build_in_parts_compiles_each_in_its_own_process_and_says_what_they_left_out(
    tmp_path: Path,
) -> None:
    exports = [
        Export(f"m:{k}", f"m__{k}__{i}", None, kernel)
        for k, i in [("good", 0), ("bad", 0), ("good", 1), ("also", 0)]
    ]
    FakeCompiler.modules = []
    assert build_parts("cpr_kernels_x", exports, tmp_path, FakeCompiler, parts=2) == (["m:bad"], 2)
    assert (tmp_path / "cpr_kernels_x.so").read_text() == "m__good__0 m__good__1 m__also__0"
    assert (tmp_path / "cpr_kernels_x_part1.so").read_text() == ""  # its one kernel left out
    assert FakeCompiler.modules == []  # compiled in other processes

    class Broken(FakeCompiler):
        def compile(self) -> None:
            raise OSError("cc: not found")

    with pytest.raises(RuntimeError, match=r"(?s)could not be compiled.*cc: not found"):
        build_parts("cpr_kernels_y", exports, tmp_path, Broken, parts=2)


def test_a_build_in_parts_loads_as_one_and_a_missing_part_is_no_build(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(ahead, "SUFFIX", ".py")  # Python files standing in for the extension modules
    name = "cpr_kernels_x"
    (tmp_path / f"{name}.json").write_text(
        json.dumps({"m:a": [[["float"]]], "m:b": [[["float"]], [["int"]]]})
    )
    (tmp_path / f"{name}.py").write_text(f"{export_name('m', 'a', 0)} = 'a0'\n")
    part = tmp_path / f"{name}_part1.py"
    part.write_text(f"{export_name('m', 'b', 0)} = 'b0'\n{export_name('m', 'b', 1)} = 'b1'\n")
    kernels = kernels_in(tmp_path, name)
    assert kernels is not None and kernels.path == tmp_path / f"{name}.py"
    loaded = [getattr(kernels.module, export_name("m", k, i)) for k, i in [("a", 0), ("b", 0), ("b", 1)]]
    assert loaded == ["a0", "b0", "b1"]
    part.unlink()
    assert kernels_in(tmp_path, name) is None  # its signatures name exports no module holds


def test_just_in_time_only_fills_numbas_cache_and_needs_no_c_compiler(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from planning import ahead_of_time

    warmed: list[tuple[list[Path], list[Path], bool, str]] = []

    def warm(urdfs: list[Path], srdfs: list[Path], bundled_only: bool) -> None:
        warmed.append((urdfs, srdfs, bundled_only, os.environ[MODE_VARIABLE]))

    monkeypatch.setattr(ahead_of_time, "_warm_robots", warm)
    monkeypatch.setattr(shutil, "which", lambda name: None)  # no C compiler: none needed
    monkeypatch.setenv(MODE_VARIABLE, "ahead")
    assert ahead_of_time.main(["--just-in-time", "--robot", "arm.urdf", "--srdf", "arm.srdf"]) == 0
    assert warmed == [([Path("arm.urdf")], [Path("arm.srdf")], False, "jit")]  # numba's dispatchers run
    assert "the kernels are in numba's disk cache" in capsys.readouterr().out
