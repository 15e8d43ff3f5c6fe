"""``scripts/startup_floor.py``: the stack's start-up floor, without a module of ours."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import SCRIPTS


@pytest.mark.slow
def test_the_floor_imports_the_stack_and_calls_a_kernel_but_nothing_of_ours() -> None:
    run = subprocess.run(
        [sys.executable, "-X", "importtime", str(SCRIPTS / "startup_floor.py")],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    imported = {line.split("|")[-1].strip() for line in run.stderr.splitlines() if "|" in line}
    assert {"pinocchio", "coal", "numba", "scipy.linalg"} <= imported
    assert "numba.np.arraymath" in imported  # a kernel was called: numba's registries loaded
    assert not {name for name in imported if name.split(".")[0] in ("planning", "cpr_kin")}
