"""The kernels compiled ahead of time: extension modules, loaded without numba.

A new process that calls a numba kernel pays for numba before the kernel's own code runs,
cached or not: its import and its first dispatch (its typing and lowering registries, and
SciPy's linear algebra, which it probes for BLAS), then each cached kernel's load
(docs/benchmarks.md: the new-process row). ``python -m planning.ahead_of_time`` compiles every
kernel a warm-up calls, with the argument types it calls them with, into extension modules
(numba's ``pycc``, one part per core) and writes beside them what those types are (:class:`Kernels`).

Here each kernel is a guard: its arguments are checked against each compiled signature, as
numba's dispatcher would type them (an array's dtype, dimensions, layout and writability; a
float, an int, a bool; a tuple's items), and where one matches, the compiled code runs; where
none does, the kernel is compiled just in time by numba, as without the module. The module is
named after the kernel files' digest (:func:`~cpr_kin.common.kernel_sources.sources_digest`;
:mod:`cpr_kin.common.kernel_files`): a changed kernel file leaves it unused.
``CPR_KERNELS=jit`` (or numba's ``NUMBA_DISABLE_JIT=1``) never loads it.
"""

from __future__ import annotations

import functools
import importlib.util
import inspect
import itertools
import json
import marshal
import os
from collections.abc import Callable, Iterable
from pathlib import Path
from types import CodeType, SimpleNamespace
from typing import Any

import numpy as np

from cpr_kin.common.kernel_files import (
    SUFFIX,
    export_name,
    guards_file,
    kernel_folders,
    kernel_key,
    module_name,
    part_name,
)
from cpr_kin.common.kernel_sources import sources_digest

MODE_VARIABLE = "CPR_KERNELS"
"""The environment variable that chooses: ``jit`` never loads the kernels compiled ahead of time."""


class Kernels:
    """The compiled kernels' exports and, per kernel, the argument types of each export.

    Args:
        module: the exports as attributes, those of the build's extension modules (``None`` where
            only the guards' code is made, by the build).
        signatures: ``{"module:name": [argument specs of export 0, of export 1, ...]}``; a spec
            is ``["array", dtype, ndim, layout, readonly]``, ``["float"]``, ``["int"]``,
            ``["bool"]`` or ``["tuple", [item specs]]``.
        codes: ``{"module:name": (source, code)}``, guards compiled before
            (:meth:`guard_codes`), used where their source is the one to compile.
        path: the build's first extension module, where loaded from one.
    """

    def __init__(
        self,
        module: object | None,
        signatures: dict[str, list[list[Any]]],
        codes: dict[str, tuple[str, CodeType]] | None = None,
        path: Path | None = None,
    ) -> None:
        self.module, self.signatures, self.codes, self.path = module, signatures, codes or {}, path

    def guarded(
        self, function: Callable[..., Any], fallback: Callable[[], Callable[..., Any]]
    ) -> Callable[..., Any]:
        """``function`` run by its exports where its arguments' types match one's, else by ``fallback()``.

        ``fallback`` is asked once, at the first call that matches no export; a kernel with no
        export always falls back.
        """
        made = self._guard_source(function)
        if made is None:  # not a kernel's parameters
            return _falling_back(function, fallback)
        source, cells = made
        exports = {
            f"_export{i}": getattr(self.module, export_name(function.__module__, function.__name__, i))
            for i in range(len(self.signatures.get(kernel_key(function), [])))
        }
        names: dict[str, Any] = {}
        exec(self._code(function, source), names)
        guard = names["_make"](_fallback=fallback, **cells, **exports)
        guard.__doc__, guard.__module__, guard.__qualname__ = (
            function.__doc__,
            function.__module__,
            function.__qualname__,
        )
        guard.__wrapped__ = function
        return guard  # type: ignore[no-any-return]

    def guard_codes(self, functions: Iterable[Callable[..., Any]]) -> dict[str, tuple[str, CodeType]]:
        """The guards of ``functions``, their source and its compiled code, for :func:`guards_file`.

        Compiling the guards is most of the time they take to make: the build keeps the code,
        and a later process uses it where the source it would compile is the same.
        """
        codes = {}
        for function in functions:
            made = self._guard_source(function)
            if made is not None:
                codes[kernel_key(function)] = (made[0], self._code(function, made[0]))
        return codes

    def _code(self, function: Callable[..., Any], source: str) -> CodeType:
        """``source`` compiled, or the code kept for it."""
        kept = self.codes.get(key := kernel_key(function))
        if kept is not None and kept[0] == source:
            return kept[1]
        return compile(source, f"<compiled ahead: {key}>", "exec")

    def _guard_source(self, function: Callable[..., Any]) -> tuple[str, dict[str, Any]] | None:
        """The source of ``_make``, which returns ``function``'s guard, and its constant arguments.

        ``None`` for a function whose parameters are not a kernel's.
        """
        key = kernel_key(function)
        parameters = list(inspect.signature(function).parameters.values())
        if any(p.kind != p.POSITIONAL_OR_KEYWORD for p in parameters):
            return None
        arguments = [p.name for p in parameters]
        # the guard is a closure: its constants and the arguments kept are cells, faster than globals
        cells: dict[str, Any] = {"_ndarray": np.ndarray, "_jit": []}
        cells |= {f"_default{i}": p.default for i, p in enumerate(parameters) if p.default is not p.empty}
        heading = ", ".join(
            a if f"_default{i}" not in cells else f"{a}=_default{i}" for i, a in enumerate(arguments)
        )
        body, kept = [], []
        signatures = self.signatures.get(key, [])
        for index, specs in enumerate(signatures):
            checks = []
            for i, (spec, argument) in enumerate(zip(specs, arguments, strict=True)):
                check = _check(spec, argument, cells)
                if spec[0] not in SCALARS:  # the object that passed last is not checked again
                    kept.append(last := f"_last{index}_{i}")
                    check = f"({argument} is {last} or ({check} and ({last} := {argument}) is {argument}))"
                checks.append(check)
            body += [
                f"        if {' and '.join(checks) or 'True'}:",
                f"            return _export{index}({', '.join(arguments)})",
            ]
        parameters_of_make = ["_fallback", *sorted(cells), *(f"_export{i}" for i in range(len(signatures)))]
        lines = [
            f"def _make({', '.join(parameters_of_make)}):",
            *(f"    {last} = None" for last in kept),
            f"    def {function.__name__}({heading}):",
            *([f"        nonlocal {', '.join(kept)}"] if kept else []),
            *body,
            "        if not _jit:",
            "            _jit.append(_fallback())",
            f"        return _jit[0]({', '.join(arguments)})",
            f"    return {function.__name__}",
        ]
        return "\n".join(lines), cells


SCALARS = ("float", "int", "bool")


def _falling_back(
    function: Callable[..., Any], fallback: Callable[[], Callable[..., Any]]
) -> Callable[..., Any]:
    """``function`` run by ``fallback()``, asked at the first call."""
    jit: list[Callable[..., Any]] = []

    @functools.wraps(function)
    def guard(*args: Any, **kwargs: Any) -> Any:
        if not jit:
            jit.append(fallback())
        return jit[0](*args, **kwargs)

    return guard


def _check(spec: list[Any], value: str, names: dict[str, Any]) -> str:
    """A Python expression: whether ``value`` has the type ``spec`` describes (numba's typing of it)."""
    kind = spec[0]
    if kind == "array":
        _, dtype, ndim, layout, readonly = spec
        dtype_name = f"_dtype_{dtype}"
        names[dtype_name] = np.dtype(dtype)
        # a dtype equal to NumPy's is not always the same object (an array numba returned)
        same_dtype = f"({value}.dtype is {dtype_name} or {value}.dtype == {dtype_name})"
        check = f"type({value}) is _ndarray and {same_dtype} and {value}.ndim == {ndim}"
        if layout == "C":  # CARRAY: C-contiguous, aligned, writeable
            check += f" and {value}.flags.{'c_contiguous' if readonly else 'carray'}"
        elif layout == "F":
            check += f" and {value}.flags.{'f_contiguous' if readonly else 'farray'}"
        elif not readonly:
            check += f" and {value}.flags.writeable"
        return f"({check})"
    if kind == "float":
        return f"(type({value}) is float or type({value}) is _float64)" + _named(
            names, "_float64", np.float64
        )
    if kind == "int":
        return f"(type({value}) is int or type({value}) is _int64)" + _named(names, "_int64", np.int64)
    if kind == "bool":
        return f"(type({value}) is bool or type({value}) is _bool)" + _named(names, "_bool", np.bool_)
    items = spec[1]
    item_checks = [_check(item, f"{value}[{i}]", names) for i, item in enumerate(items)]
    size = f"isinstance({value}, tuple) and len({value}) == {len(items)}"
    return f"({' and '.join([size, *item_checks])})"


def _named(names: dict[str, Any], name: str, value: Any) -> str:
    """``""``, with ``value`` put in ``names`` as ``name``."""
    names[name] = value
    return ""


def load_kernels(folders: list[Path] | None = None) -> Kernels | None:
    """The kernels compiled ahead of time for today's kernel files, or ``None``.

    ``None`` where :data:`MODE_VARIABLE` is ``jit``, numba's JIT is disabled, no folder holds a
    module for the kernel files' digest with its signatures, or it cannot be loaded.
    """
    if os.environ.get(MODE_VARIABLE) == "jit" or os.environ.get("NUMBA_DISABLE_JIT", "0") not in ("", "0"):
        return None
    name = module_name(sources_digest())
    for folder in kernel_folders() if folders is None else folders:
        kernels = kernels_in(folder, name)
        if kernels is not None:
            return kernels
    return None


def kernels_in(folder: Path, name: str) -> Kernels | None:
    """The build ``name`` in ``folder``, its signatures and its guards' code; ``None``: not loadable.

    Its extension modules (``name`` and its other parts, :func:`~cpr_kin.common.kernel_files.part_name`)
    are loaded into one namespace, which must hold every export its signatures name.
    """
    path, signatures = folder / f"{name}{SUFFIX}", folder / f"{name}.json"
    if not (path.is_file() and signatures.is_file()):
        return None
    try:
        exports = SimpleNamespace()
        for part in itertools.count():
            file = folder / f"{part_name(name, part)}{SUFFIX}"
            if not file.is_file():
                break
            spec = importlib.util.spec_from_file_location(part_name(name, part), file)
            if spec is None or spec.loader is None:
                return None
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            vars(exports).update(vars(module))
        specs = json.loads(signatures.read_text())
        for key, exported in specs.items():  # a part missing: no build
            owner, _, kernel = key.partition(":")
            if not all(hasattr(exports, export_name(owner, kernel, i)) for i in range(len(exported))):
                return None
        return Kernels(exports, specs, kept_codes(folder / guards_file(name)), path)
    except (ImportError, OSError, ValueError, TypeError):
        return None


def write_codes(path: Path, codes: dict[str, tuple[str, CodeType]]) -> None:
    """Write the guards' code ``codes`` (:meth:`Kernels.guard_codes`) to ``path``.

    Marked, as a ``.pyc`` is, with this Python's bytecode version (:func:`kept_codes` reads it).
    """
    path.write_bytes(marshal.dumps((importlib.util.MAGIC_NUMBER, codes)))


def kept_codes(path: Path) -> dict[str, tuple[str, CodeType]]:
    """The guards' code :func:`write_codes` wrote in ``path``.

    Empty where it cannot be read, or is of another bytecode version.
    """
    try:
        magic, codes = marshal.loads(path.read_bytes())
    except (OSError, EOFError, ValueError, TypeError):
        return {}
    if magic != importlib.util.MAGIC_NUMBER or not isinstance(codes, dict):
        return {}
    return {k: v for k, v in codes.items() if isinstance(v, tuple) and [*map(type, v)] == [str, CodeType]}
