"""The packages' public APIs (lazy exports, lazy_loader) and what their import costs."""

from __future__ import annotations

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest


@pytest.mark.parametrize("package", ["cpr_kin", "planning"])
def test_every_export_resolves_to_its_module_object(package: str) -> None:
    module = importlib.import_module(package)
    stub = Path(module.__file__ or "").with_suffix(".pyi")
    imported = {
        alias.name: f"{package}.{node.module}"
        for node in ast.walk(ast.parse(stub.read_text()))
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }
    assert sorted(module.__all__) == sorted(imported)  # the stub's __all__ lists what it imports
    assert set(imported) <= set(dir(module))
    for name, source in imported.items():
        assert getattr(module, name) is getattr(importlib.import_module(source), name), name
    with pytest.raises(AttributeError, match="no_such_name"):
        _ = module.no_such_name


def test_the_batch_parent_imports_no_planner_robot_or_compiler() -> None:
    # `cpr-plan batch` dispatches scenes to workers: its process needs none of the heavy
    # modules (numba, coal, Pinocchio, SciPy, trimesh: about 1.2 s), which each worker imports
    heavy = ["numba", "coal", "pinocchio", "scipy", "trimesh", "yourdfpy", "planning.planner"]
    code = (
        "import sys, cpr_kin, planning, planning.cli, planning.batch, planning.report, "
        "planning.trajectory_io; "
        f"print(*[m in sys.modules for m in {heavy!r}])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert dict(zip(heavy, out.split(), strict=True)) == dict.fromkeys(heavy, "False")


def test_loading_a_robot_imports_what_it_needs() -> None:
    # attribute access imports the module behind it; the bundled URDF, which the tests
    # validate, loads without yourdfpy (and trimesh)
    modules = ["pinocchio", "coal", "yourdfpy", "trimesh"]
    code = f"import sys, cpr_kin as ck; ck.load_cpr(); print(*[m in sys.modules for m in {modules!r}])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "True", "False", "False"]
