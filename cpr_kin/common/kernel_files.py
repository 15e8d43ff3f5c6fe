"""Where the kernels compiled ahead of time are, and what their files are called.

One build (:mod:`planning.ahead_of_time`) writes its files into the first writable of
:func:`kernel_folders`, each named after the kernel files' digest and the machine's CPU
(:func:`module_name`): the extension module (and its other parts, :func:`part_name`), its
signatures (``.json``) and its guards' code (:func:`guards_file`); :mod:`cpr_kin.common.ahead`
loads them.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import importlib.machinery
import os
import platform
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

SUFFIX = importlib.machinery.EXTENSION_SUFFIXES[0]


def module_name(digest: str) -> str:
    """The extension module's name for the kernel files' digest ``digest``, on this machine's CPU.

    The module is compiled for the host CPU (as numba compiles): one built on another machine
    (a home folder shared between machines) has another name.
    """
    return f"cpr_kernels_{digest[:20]}_{host_key()}"


@functools.cache
def host_key() -> str:
    """A short digest of this machine's CPU: its architecture, model and features where the system says."""
    described = platform.machine()
    with contextlib.suppress(OSError):
        lines = Path("/proc/cpuinfo").read_text().splitlines()
        described += "".join(sorted({line for line in lines if line.startswith(("model name", "flags"))}))
    return hashlib.sha256(described.encode()).hexdigest()[:8]


def part_name(module: str, part: int) -> str:
    """The name of part ``part`` of the build ``module`` (:func:`module_name`); part 0 is ``module``.

    A build may compile its kernels into several extension modules at once, one per core.
    """
    return module if part == 0 else f"{module}_part{part}"


def guards_file(module: str) -> str:
    """The name of the file beside ``module`` (:func:`module_name`) holding its guards' code.

    Compiled Python code, read by this version of Python only (its cache tag is in the name).
    """
    return f"{module}.{sys.implementation.cache_tag}.guards"


FOLDER_VARIABLE = "CPR_KERNELS_DIR"
"""The environment variable naming the module's one folder, instead of :func:`kernel_folders`' defaults."""


def kernel_folders() -> list[Path]:
    """Where the module is looked for and built, first first.

    :data:`FOLDER_VARIABLE`'s folder alone where set; else the package's ``__pycache__``, then the
    user's cache.
    """
    if os.environ.get(FOLDER_VARIABLE):
        return [Path(os.environ[FOLDER_VARIABLE])]
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return [Path(__file__).resolve().parent / "__pycache__", cache / "cpr-firefly" / "kernels"]


def kernel_key(function: Callable[..., Any]) -> str:
    """A kernel's name in the signatures file: ``module:name``."""
    return f"{function.__module__}:{function.__name__}"


def export_name(module: str, name: str, index: int) -> str:
    """The name in the extension module of signature ``index`` of kernel ``name`` of ``module``."""
    return f"{module.replace('.', '_')}__{name}__{index}"
