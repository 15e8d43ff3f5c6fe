"""numba's ``pycc`` compiling kernels into extension modules, several at once where the machine can.

:mod:`planning.ahead_of_time` runs the warm-up, which chooses the kernels and their signatures;
here they are compiled. ``pycc`` compiles one module on one core: the exports are split by kernel
into parts, one extension module each, compiled in forked processes at once (on Linux, where a
forked process may go on compiling; elsewhere one after the other in this process). The first
part is named as the build, the others ``<name>_part<i>``
(:func:`~cpr_kin.common.kernel_files.part_name`); :mod:`cpr_kin.common.ahead` loads them all.
"""

from __future__ import annotations

import functools
import json
import os
import sys
import tempfile
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cpr_kin.common.kernel_files import part_name


@dataclass(frozen=True)
class Export:
    """One compiled signature of a kernel.

    Attributes:
        key: the kernel, ``module:name``.
        name: its name in the extension module (:func:`~cpr_kin.common.kernel_files.export_name`).
        signature: numba's signature of it.
        function: the kernel's Python function.
    """

    key: str
    name: str
    signature: Any
    function: Callable[..., Any]


def build_module(
    name: str, exports: Sequence[Export], folder: Path, compiler: Callable[[str], Any]
) -> list[str]:
    """Compile ``exports`` into the extension module ``name`` in ``folder``; the kernels it left out.

    ``compiler`` is numba's ``pycc.CC``. It compiles a module's exports together, and one it
    cannot compile fails them all: then each kernel is compiled alone, into a module that is
    thrown away, and the module is built without those that fail (numba compiles them just in
    time, as without a build).
    """

    def compile_into(chosen: Sequence[Export], module: str, output: Path) -> None:
        build = compiler(module)
        build.target_cpu = "host"
        build.output_dir = str(output)
        for export in chosen:
            build.export(export.name, export.signature)(export.function)
        build.compile()

    try:
        compile_into(exports, name, folder)
        return []
    except Exception:  # numba's typing or lowering, or the C compiler: its errors share no base class
        pass
    failed = []
    for key in dict.fromkeys(export.key for export in exports):
        with tempfile.TemporaryDirectory(dir=folder) as alone:
            try:
                compile_into([e for e in exports if e.key == key], f"{name}_alone", Path(alone))
            except Exception:
                failed.append(key)
    compile_into([e for e in exports if e.key not in failed], name, folder)
    return failed


def split_by_kernel(exports: Sequence[Export], parts: int) -> list[list[Export]]:
    """``exports`` in at most ``parts`` non-empty parts, every signature of a kernel in the same part.

    The kernels are dealt out in turn, in their order: the parts differ by one kernel at most.
    """
    turn = {key: i % max(1, parts) for i, key in enumerate(dict.fromkeys(e.key for e in exports))}
    dealt = [[e for e in exports if turn[e.key] == i] for i in range(max(1, parts))]
    return [part for part in dealt if part]


def build_parts(
    name: str, exports: Sequence[Export], folder: Path, compiler: Callable[[str], Any], parts: int
) -> tuple[list[str], int]:
    """Compile ``exports`` into up to ``parts`` extension modules in ``folder``, at once where forking.

    Each part is :func:`build_module`'s; returns the kernels left out and the number of modules.
    A part that fails in its process raises here, with that process's traceback.
    """
    split = split_by_kernel(exports, parts)
    names = [part_name(name, i) for i in range(len(split))]
    if len(split) == 1 or not sys.platform.startswith("linux"):
        left = [
            build_module(module, part, folder, compiler) for part, module in zip(split, names, strict=True)
        ]
        return [key for keys in left for key in keys], len(split)
    sys.stdout.flush()  # nothing buffered here is written twice, by a child too
    sys.stderr.flush()
    children = [
        _forked(functools.partial(build_module, module, part, folder, compiler))
        for part, module in zip(split, names, strict=True)
    ]
    failed: list[str] = []
    errors = []
    for pid, pipe in children:
        with os.fdopen(pipe) as read:
            said = json.loads(read.read() or '{"error": "the process ended without a word"}')
        os.waitpid(pid, 0)
        if "error" in said:
            errors.append(said["error"])
        else:
            failed += said["failed"]
    if errors:
        raise RuntimeError("a part of the kernels could not be compiled:\n" + "\n".join(errors))
    return failed, len(split)


def _forked(work: Callable[[], list[str]]) -> tuple[int, int]:
    """``work`` run in a forked process: its id, and the pipe it writes its answer to (JSON)."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: answers, then ends without running this process's exit handlers
        os.close(read)
        try:
            answer: dict[str, Any] = {"failed": work()}
        except BaseException:  # reported to the parent, which raises it
            answer = {"error": traceback.format_exc()}
        with os.fdopen(write, "w") as out:
            out.write(json.dumps(answer))
        os._exit(0)
    os.close(write)
    return pid, read
