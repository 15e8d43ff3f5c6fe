"""The project's just-in-time compiler: Numba's ``njit``, typed for mypy.

Hot loops that NumPy can only express as many small array operations (a per-configuration
kinematic chain, the firefly sweep) are compiled with Numba instead. Compiled code is cached
on disk (``cache=True``), so only the first run on a machine pays for compilation. Setting
``NUMBA_DISABLE_JIT=1`` runs the same functions as plain Python, for debugging.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import numba

F = TypeVar("F", bound=Callable[..., Any])


def njit(function: F) -> F:
    """Compile ``function`` in nopython mode, cached, releasing the GIL."""
    return cast(F, numba.njit(cache=True, nogil=True)(function))


def njit_inline(function: F) -> F:
    """:func:`njit`, and inlined into the compiled functions that call it.

    For a small helper called in a compiled loop: passing it arrays costs their reference
    counts at every call, which can outweigh its work (``docs/benchmarks.md``, stop 59).
    """
    return cast(F, numba.njit(cache=True, nogil=True, inline="always")(function))
