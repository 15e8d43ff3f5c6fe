"""The packages' public APIs (lazy exports, lazy_loader) and what their import costs."""

from __future__ import annotations

import ast
import importlib
import os
import shutil
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest


@pytest.mark.parametrize(
    "package",
    [
        "cpr_kin",
        "planning",
        "planning.curves",
        "planning.search",
        "planning.io",
        "planning.viz",
        "planning.bench",
    ],
)
def test_every_export_resolves_to_its_module_object(package: str) -> None:
    module = importlib.import_module(package)
    stub = Path(module.__file__ or "").with_suffix(".pyi")
    imported = {  # name -> the module it comes from (`from . import x`: the submodule x itself)
        alias.name: f"{package}.{node.module}" if node.module else f"{package}.{alias.name}"
        for node in ast.walk(ast.parse(stub.read_text()))
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
    }
    assert sorted(module.__all__) == sorted(imported)  # the stub's __all__ lists what it imports
    assert set(imported) <= set(dir(module))
    for name, source in imported.items():
        expected = importlib.import_module(source)
        if not source.endswith(f".{name}"):
            expected = getattr(expected, name)
        assert getattr(module, name) is expected, name
    with pytest.raises(AttributeError, match="no_such_name"):
        _ = module.no_such_name


def test_pyproject_names_every_package_of_the_tree() -> None:
    # the packages are listed by name (one is mapped from the top-level urdf/): a new one must be named
    root = Path(__file__).resolve().parents[1]
    listed = set(tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    folders = [f for top in ("cpr_kin", "planning") for f in [root / top, *(root / top).rglob("*")]]
    tree = {
        ".".join(folder.relative_to(root).parts)
        for folder in folders
        if folder.is_dir() and folder.name != "__pycache__" and any(folder.glob("*.*"))
    }
    tree |= {"cpr_kin.urdf", "cpr_kin.urdf.makers"}  # package-dir: urdf/ and urdf/makers/
    assert listed == tree, f"not listed: {sorted(tree - listed)}; no such folder: {sorted(listed - tree)}"


@pytest.mark.slow
def test_the_batch_parent_imports_no_planner_robot_or_compiler() -> None:
    # `cpr-plan batch` dispatches scenes to workers: its process needs none of the heavy
    # modules (numba, coal, Pinocchio, SciPy, trimesh: about 1.2 s), which each worker imports
    heavy = ["numba", "coal", "pinocchio", "scipy", "trimesh", "yourdfpy", "planning.pipeline.planner"]
    code = (
        "import sys, cpr_kin, planning, planning.cli, planning.batch, planning.io.report, "
        "planning.io.trajectory_io; "
        f"print(*[m in sys.modules for m in {heavy!r}])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert dict(zip(heavy, out.split(), strict=True)) == dict.fromkeys(heavy, "False")


@pytest.mark.slow
def test_the_shared_helpers_load_no_robot() -> None:
    # planning shows values, reads user files and raises the robot's errors through
    # cpr_kin.common, which loads no robot module and none of the libraries a robot needs
    heavy = ["numpy", "numba", "coal", "pinocchio", "cpr_kin.model", "cpr_kin.shapes", "cpr_kin.description"]
    code = (
        "import sys, cpr_kin.common.names, cpr_kin.common.user_files, cpr_kin.common.errors; "
        f"print(*[m in sys.modules for m in {heavy!r}])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert dict(zip(heavy, out.split(), strict=True)) == dict.fromkeys(heavy, "False")


@pytest.mark.slow
def test_loading_a_robot_imports_what_it_needs() -> None:
    # attribute access imports the module behind it; the bundled URDF, which the tests
    # validate, loads without yourdfpy (and trimesh)
    modules = ["pinocchio", "coal", "yourdfpy", "trimesh"]
    code = f"import sys, cpr_kin as ck; ck.load_cpr(); print(*[m in sys.modules for m in {modules!r}])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["True", "True", "False", "False"]


@pytest.mark.slow
def test_a_plan_among_primitives_imports_no_scipy_module_it_does_not_use() -> None:
    # SciPy's ndimage (a running minimum of the timing's local caps) and spatial (the convex
    # hull of a box's eight corners) took 0.1 s of every new process that planned the shelf
    modules = ["scipy.ndimage", "scipy.spatial"]
    code = (
        "import sys, cpr_kin as ck; from planning import load_scene, plan; from planning.io.bundled "
        "import bundled_scene_paths; plan(load_scene(bundled_scene_paths()[1]), ck.load_cpr()); "
        f"print(*[m in sys.modules for m in {modules!r}])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


@pytest.mark.slow
def test_cpr_plan_plan_imports_no_benchmark_module(tmp_path: Path) -> None:
    # the generators, MotionBenchMaker and the peers live in planning.bench, outside what a plan needs
    code = (
        "import sys; from planning.cli import main; from planning.io.bundled import bundled_scene_paths; "
        f"code = main(['plan', str(bundled_scene_paths()[1]), '--out', {str(tmp_path / 'out')!r}]); "
        "print(code, sorted(m for m in sys.modules if m.startswith('planning.bench')))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split("\n")[-2] == "0 []"


@pytest.mark.slow
def test_a_plan_of_the_cpr_imports_no_machinery_for_what_its_scene_lacks(tmp_path: Path) -> None:
    # no pairs of its own, no cloud, a tool position its own IK reaches, no mesh:
    # a new process of `cpr-plan plan` does not pay for the modules of those (docs/benchmarks.md)
    unused = [
        "cpr_kin.collision.self_screen",  # the self-collision screen of a robot with pairs
        "cpr_kin.bounds.self_bounds",
        "cpr_kin.certified.self_curve",
        "cpr_kin.collision.self_filter",  # a point cloud's voxels
        "cpr_kin.shapes.octree_files",
        "cpr_kin.kinematics.numerical_ik",  # the CPR's analytic IK, verified by an IkTarget
        "cpr_kin.shapes.exact_meshes",  # links given as meshes, and their vertices' witness
        "cpr_kin.shapes.vertex_witness",
    ]
    code = (
        "import sys; from planning.cli import main; from planning.io.bundled import bundled_scene_paths; "
        "from cpr_kin.model.packages import example_robot_data_share as share; "
        f"code = main(['plan', str(bundled_scene_paths()[1]), '--out', {str(tmp_path / 'out')!r}]); "
        f"print(code, share.cache_info().currsize, *[m in sys.modules for m in {unused!r}])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split("\n")[-2].split() == ["0", "0", *["False"] * len(unused)]


@pytest.mark.slow
def test_an_installed_wheel_carries_its_data_and_stubs(tmp_path: Path) -> None:
    # the wheel, not the checkout: the URDF, limits and scenes as package data, and the
    # __init__.pyi stubs that the lazy exports are read from
    root = Path(__file__).resolve().parents[1]
    source = tmp_path / "source"
    shutil.copytree(
        root, source, ignore=shutil.ignore_patterns(".*", "build", "out", "*.egg-info", "__pycache__")
    )
    pip = [sys.executable, "-m", "pip", "--disable-pip-version-check", "--quiet"]
    subprocess.run([*pip, "wheel", str(source), "--no-deps", "-w", str(tmp_path / "dist")], check=True)
    wheel = next((tmp_path / "dist").glob("cpr_firefly-*.whl"))
    # every package of the checkout is in the wheel (a hand-written list once missed planning.cli)
    names = zipfile.ZipFile(wheel).namelist()
    packed = {str(Path(name).parent) for name in names if name.endswith(".py")}
    packages = {
        str(init.parent.relative_to(root))
        for top in ("cpr_kin", "planning")
        for init in (root / top).rglob("__init__.py")
    }
    assert packages <= packed, sorted(packages - packed)
    # the top-level urdf/ folder is the package cpr_kin.urdf (pyproject's package-dir), every file of it
    bundled = {f"cpr_kin/urdf/{p.relative_to(root / 'urdf')}" for p in (root / "urdf").rglob("*.*")}
    bundled = {name for name in bundled if "__pycache__" not in name}
    assert bundled and bundled <= set(names), sorted(bundled - set(names))
    site = tmp_path / "site"
    subprocess.run([*pip, "install", "--no-deps", "--target", str(site), str(wheel)], check=True)
    code = (
        "import cpr_kin, planning, planning.curves, planning.io; "
        "robot = cpr_kin.load_cpr(); scene = planning.io.paper_scene(); "
        "print(cpr_kin.__file__, robot.urdf_path, scene.name, planning.plan.__module__, "
        "planning.curves.SepticSplineSolver.__module__, sep='\\n')"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        env={**os.environ, "PYTHONPATH": str(site)},  # before the checkout's editable install
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split("\n")
    assert out[0].startswith(str(site)) and out[1].startswith(str(site))
    assert out[1].endswith("cpr.urdf") and out[2:5] == [
        "paper",
        "planning.pipeline.planner",
        "planning.curves.spline",
    ]
    for package in ("cpr_kin", "planning"):  # PEP 561: the packages carry their own types
        assert (site / package / "py.typed").is_file()
