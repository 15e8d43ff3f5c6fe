"""``scripts/startup_floor.py``: the libraries a plan imports, without a module of ours."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import SCRIPTS


def imported_by(arguments: list[str]) -> set[str]:
    """The modules ``python -X importtime ARGUMENTS`` imports."""
    run = subprocess.run(
        [sys.executable, "-X", "importtime", *arguments],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    return {line.split("|")[-1].strip() for line in run.stderr.splitlines() if "|" in line}


@pytest.mark.slow
def test_the_floor_imports_the_libraries_a_plan_imports_and_nothing_of_ours() -> None:
    floor = imported_by([str(SCRIPTS / "startup_floor.py")])
    assert {
        "numpy.random",
        "pinocchio",
        "coal",
        "pydantic._internal._model_construction",
        "pydantic.types",
        "annotated_types",
        "yaml",
        "lxml.etree",
    } <= floor
    assert not {name for name in floor if name.split(".")[0] in ("planning", "cpr_kin", "numba", "scipy")}
