"""The project's compiler of hot loops: numba's ``njit``, typed for mypy, or the kernels compiled ahead.

Hot loops that NumPy can only express as many small array operations (a per-configuration
kinematic chain, the firefly sweep) are compiled with numba instead. Where the kernels were
compiled ahead of time for today's sources (``python -m planning.ahead_of_time``;
:mod:`cpr_kin.common.ahead`), a kernel runs that code and numba is not imported, unless a call
brings argument types none was compiled for: numba then compiles that kernel, and the kernels
it calls, for those (:func:`_just_in_time`); the others keep the code compiled ahead of time.
Otherwise numba compiles each kernel on its first
call and caches the code on disk (:mod:`cpr_kin.common.just_in_time`), so only the first run on
a machine pays for compilation. Setting ``NUMBA_DISABLE_JIT=1`` runs the same functions as plain
Python, for debugging; ``CPR_KERNELS=jit`` compiles just in time even where a module compiled
ahead of time exists.

A compilation keeps a first run waiting with nothing to show for it; the first of a process is
said on the logger named :data:`COMPILE_LOG` (``INFO``), which ``cpr-plan`` prints on stderr.
"""

from __future__ import annotations

import types
from collections.abc import Callable
from typing import Any, TypeVar, cast

from cpr_kin.common.ahead import Kernels, load_kernels

F = TypeVar("F", bound=Callable[..., Any])

COMPILE_LOG = "cpr_kin.compiled"
"""The logger where the first compilation of a process is said (``logging`` is imported only then)."""
COMPILING = (
    "compiling the numba kernels, which the first run on a machine (or after an update) does once: "
    "tens of seconds; later runs load them from the disk cache"
)
"""What is said."""

_AHEAD: list[Kernels | None] = []
_KERNELS: dict[Callable[..., Any], bool] = {}
"""Every kernel's function, and whether it is inlined: what :func:`_just_in_time` compiles."""
_JIT: dict[Callable[..., Any], Callable[..., Any]] = {}
"""Every kernel's numba dispatcher, where no kernels compiled ahead of time were loaded."""
_ALONE: dict[Callable[..., Any], Callable[..., Any]] = {}
"""The dispatchers of the kernels called with types no export takes, and of the kernels they call."""


def compile_seconds() -> float:
    """The wall time numba has spent compiling the kernels in this process [s]: 0 where it compiled none.

    The first run on a machine (or after an update) compiles them; kernels compiled ahead of
    time are not. A plan's time limit leaves this time out (:mod:`planning.pipeline.deadline`).
    """
    if not _JIT and not _ALONE:
        return 0.0  # every kernel compiled ahead of time, or none made yet: numba not imported
    from cpr_kin.common.just_in_time import compile_seconds as seconds

    return seconds()


def njit(function: F) -> F:
    """Compile ``function`` in nopython mode, cached, releasing the GIL."""
    return cast(F, _kernel(function, inline=False))


def njit_inline(function: F) -> F:
    """:func:`njit`, and inlined into the compiled functions that call it.

    For a small helper called in a compiled loop: passing it arrays costs their reference
    counts at every call, which can outweigh its work (``docs/benchmarks.md``, stop 59).
    """
    return cast(F, _kernel(function, inline=True))


def _kernel(function: Callable[..., Any], inline: bool) -> Callable[..., Any]:
    """The kernel of ``function``: its code compiled ahead of time behind a guard, or numba's."""
    _KERNELS[function] = inline
    if not _AHEAD:
        _AHEAD.append(load_kernels())
    ahead = _AHEAD[0]
    if ahead is None or _JIT:
        return _dispatcher(function)
    return ahead.guarded(function, lambda: _just_in_time(function))


def _dispatcher(function: Callable[..., Any]) -> Callable[..., Any]:
    """Numba's dispatcher of ``function``, made once."""
    if function not in _JIT:
        import logging

        from cpr_kin.common.just_in_time import jit

        _JIT[function] = jit(function, _KERNELS[function], logging.getLogger(COMPILE_LOG), COMPILING)
    return _JIT[function]


def _just_in_time(function: Callable[..., Any]) -> Callable[..., Any]:
    """Numba's dispatcher of ``function``, where a call's argument types match none compiled ahead of time.

    Numba compiles a kernel's calls of other kernels through the names its module binds them
    to, which are the guards of the code compiled ahead of time
    (:meth:`~cpr_kin.common.ahead.Kernels.guarded`): numba cannot call those. The dispatcher is
    made of a copy of ``function`` whose globals bind each kernel it calls to that kernel's own
    dispatcher, made the same way, so that numba compiles (or loads from its disk cache)
    ``function`` and the kernels it calls, no others: every other kernel, and every call of
    this one whose types an export takes, keeps running the code compiled ahead of time.
    """
    if function not in _ALONE:
        import logging

        from cpr_kin.common.just_in_time import jit

        callees = {
            name: _just_in_time(kernel)
            for name in function.__code__.co_names
            if (kernel := getattr(function.__globals__.get(name), "__wrapped__", None)) in _KERNELS
        }
        alone = function
        if callees:
            alone = types.FunctionType(
                function.__code__,
                {**function.__globals__, **callees},
                function.__name__,
                function.__defaults__,
                function.__closure__,
            )
            alone.__qualname__, alone.__module__ = function.__qualname__, function.__module__
        _ALONE[function] = jit(alone, _KERNELS[function], logging.getLogger(COMPILE_LOG), COMPILING)
    return _ALONE[function]
