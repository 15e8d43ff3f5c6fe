"""The start-up floor of a ``cpr-plan plan`` process: what the planner stands on, before a line of ours runs.

    python scripts/startup_floor.py

Imports the libraries ``cpr-plan plan`` imports, and nothing of ours: NumPy (and its random
generators), Pinocchio, coal, pydantic with its models' machinery and its fields' constraints
(and ``importlib.metadata``, which pydantic's plugin loader imports), PyYAML, lxml and
lazy_loader; no numba, which a plan with the kernels compiled ahead of time does not import
(``make kernels``), and no threadpoolctl, which the installed command does not need
(``planning.pipeline.blas_threads``). The process runs as the installed command's does: BLAS on
one thread from its start, the cyclic collector off and no teardown at its end
(``planning/cli/process.py``). ``cpr-plan plan``'s wall time less this one's is what the
planner itself adds (docs/benchmarks.md: the new-process row).
"""

from __future__ import annotations

import gc
import os
import sys

gc.disable()
os.environ["OPENBLAS_NUM_THREADS"] = "1"  # as the installed command sets it, before NumPy loads OpenBLAS

import importlib.metadata  # noqa: E402, F401 - each imported for its start-up cost

import coal  # noqa: E402, F401
import lazy_loader  # noqa: E402, F401
import lxml.etree  # noqa: E402, F401
import numpy.random  # noqa: E402, F401
import pinocchio  # noqa: E402, F401
import pydantic  # noqa: E402, F401
import yaml  # noqa: E402, F401
from pydantic import BaseModel, Field  # noqa: E402, F401 - the models' machinery, which `import pydantic` defers

if __name__ == "__main__":
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
