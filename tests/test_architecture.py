"""The package layout holds: small modules, and imports that follow the layers.

The layers are docs/architecture.md's "Packages and layers" table: each row's package may
import what its "may import" cell names and, in turn, what those may. Every import statement
is counted: at module level, inside functions and under ``if TYPE_CHECKING:``. A few rules
are also written out here: ``planning.curves`` is pure mathematics (no robot),
``planning.search`` knows only objectives over boxes, the core never imports a peer, and
drawing libraries are imported only by ``planning.viz`` (lazily elsewhere).
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ARCHITECTURE = ROOT / "docs" / "architecture.md"
PACKAGES = ("cpr_kin", "planning")
MAX_LINES = 300


def modules() -> dict[str, Path]:
    """Every module of the packages, by dotted name."""
    found = {}
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            found[name] = path
    return found


def imports(name: str, path: Path) -> list[tuple[str, bool]]:
    """``(imported module, at module level)`` of every import statement of a module."""
    tree = ast.parse(path.read_text())
    top_level = {id(node) for node in tree.body}
    top_level |= {  # imports under `if TYPE_CHECKING:` run only for the type checker
        id(child) for node in tree.body if isinstance(node, ast.If) for child in node.body
    }
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, id(node) in top_level) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*anchor, base] if base else anchor)
            found += [(base, id(node) in top_level)]
            found += [(f"{base}.{alias.name}", id(node) in top_level) for alias in node.names]
    return found


def typing_only(path: Path) -> set[str]:
    """Modules imported only under ``if TYPE_CHECKING:``."""
    tree = ast.parse(path.read_text())
    names = set()
    for node in tree.body:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in ast.walk(node):
                if isinstance(child, ast.ImportFrom) and child.module:
                    names.add(child.module)
    return names


def within(module: str, prefix: str) -> bool:
    return module == prefix or module.startswith(prefix + ".")


@pytest.mark.parametrize("name", sorted(modules()))
def test_modules_are_small(name: str) -> None:
    lines = len(modules()[name].read_text().splitlines())
    assert lines <= MAX_LINES, f"{name} has {lines} lines; split it by concept (at most {MAX_LINES})"


def test_the_core_never_imports_a_peer() -> None:
    offenders = [
        (name, imported)
        for name, path in modules().items()
        if not within(name, "planning.bench")
        for imported, _ in imports(name, path)
        if within(imported, "planning.bench")
    ]
    assert offenders == []


def test_curves_are_pure_mathematics_and_search_knows_no_robot() -> None:
    allowed = {
        "planning.curves": (
            "planning.curves",
            "planning.errors",
            "planning.validation",
            "cpr_kin.common.compiled",
            "cpr_kin.common.arrays",
            "cpr_kin.common.rest_to_rest",
        ),
        "planning.search": (
            "planning.search",
            "planning.errors",
            "planning.validation",
            "cpr_kin.common.compiled",
            "cpr_kin.common.arrays",
        ),
    }
    offenders = []
    for name, path in modules().items():
        for layer, permitted in allowed.items():
            if not within(name, layer):
                continue
            for imported, _ in imports(name, path):
                ours = within(imported, "planning") or within(imported, "cpr_kin")
                if ours and not any(within(imported, p) for p in permitted):
                    offenders.append((name, imported))
    assert offenders == []


def test_the_pipeline_knows_no_file_command_line_or_drawing() -> None:
    # scene -> problem -> search -> choose -> result: what reads and writes files, the command
    # line, the batch and the viewer are built on it, never under it
    outside = ("planning.io", "planning.cli", "planning.batch", "planning.viz", "planning.bench")
    offenders = [
        (name, imported)
        for name, path in modules().items()
        if within(name, "planning.pipeline")
        for imported, module_level in imports(name, path)
        if module_level and any(within(imported, o) for o in outside)
    ]
    assert offenders == []


MAX_PARAMETERS = 6
"""Most parameters of a pipeline function (``self`` not counted): stages hand over named values."""


def test_pipeline_functions_take_named_values_not_long_argument_lists() -> None:
    offenders = []
    for name, path in modules().items():
        if not within(name, "planning.pipeline"):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                arguments = node.args
                count = len(arguments.posonlyargs) + len(arguments.args) + len(arguments.kwonlyargs)
                count -= bool(arguments.args) and arguments.args[0].arg in ("self", "cls")
                if count > MAX_PARAMETERS:
                    offenders.append(f"{name}.{node.name} ({count})")
    assert offenders == []


def test_drawing_libraries_load_only_with_the_viewer_or_plots() -> None:
    drawing = ("meshcat", "matplotlib", "planning.viz")
    offenders = [
        (name, imported)
        for name, path in modules().items()
        if not within(name, "planning.viz")
        for imported, module_level in imports(name, path)
        if module_level and any(within(imported, d) for d in drawing) and imported not in typing_only(path)
    ]
    assert offenders == []


def test_the_checker_sees_what_it_checks() -> None:
    # the graph reader resolves relative imports and finds function-level imports
    found = imports("planning.cli.plan_commands", modules()["planning.cli.plan_commands"])
    assert ("planning.pipeline.planner", False) in found and ("planning.outcome", True) in found
    stub_reader = imports("planning.curves", ROOT / "planning" / "curves" / "__init__.py")
    assert ("lazy_loader", True) in stub_reader


def layer_rows() -> dict[str, tuple[str, str]]:
    """docs/architecture.md's "Packages and layers" table: ``{package: (holds, may import)}``."""
    text = ARCHITECTURE.read_text().split("## Packages and layers", 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in text.splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        named = re.match(r"`([a-z_.]+)`", cells[0]) if len(cells) == 3 else None
        if named:
            rows[named.group(1)] = (cells[1], cells[2])
    return rows


def row_of(name: str, rows: dict[str, tuple[str, str]]) -> str:
    """The row that holds module ``name``: its package's, the longest that contains it."""
    return max((row for row in rows if within(name, row)), key=len)


def may_import(row: str, rows: dict[str, tuple[str, str]]) -> set[str]:
    """What the modules of ``row`` may import: rows or modules by name, and what those may, in turn."""
    text = rows[row][1]
    named = set(re.findall(r"`([a-z_.]+)`", text)) | (
        {"planning.pipeline"} if "the pipeline" in text else set()
    )
    if text.startswith("nothing of"):
        named = set()
    elif text.startswith(("anything", "every package")):
        named = set(rows) - {n for n in named if n in rows or f"planning.{n}" in rows}
        named -= {f"planning.{n}" for n in re.findall(r"but `([a-z_.]+)`", text)}
    resolved = {n if n in rows or "." in n else f"planning.{n}" for n in named}
    allowed = set(resolved)
    for other in resolved & set(rows):
        if other != row:
            allowed |= may_import(other, rows)
    return allowed


def test_every_import_follows_its_row_of_the_layer_table() -> None:
    rows = layer_rows()
    offenders = []
    for name, path in modules().items():
        row = row_of(name, rows)
        allowed = may_import(row, rows)
        for imported, _ in imports(name, path):  # module level, in functions, for the type checker
            if not any(within(imported, p) for p in PACKAGES):
                continue
            target = row_of(imported, rows)  # a row allows its own modules; a module name, that module
            single = any(within(imported, a) for a in allowed if a not in rows)
            if target != row and target not in allowed and not single:
                offenders.append(f"{name} -> {imported}")
    assert offenders == [], f"imports beyond docs/architecture.md's rows: {sorted(set(offenders))}"


def test_the_layer_table_names_every_module() -> None:
    rows = layer_rows()
    missing = [
        name
        for name in modules()
        if name not in rows and f"`{name.rpartition('.')[2]}`" not in rows[row_of(name, rows)][0]
    ]
    assert missing == [], f"modules docs/architecture.md does not list in their package's row: {missing}"


def import_graph(package: str) -> dict[str, set[str]]:
    """``{module: the modules it imports}`` for the modules of ``package``, every import counted."""
    found = modules()
    graph = {}
    for name, path in found.items():
        if not within(name, package):
            continue
        targets = set()
        for imported, _ in imports(name, path):
            while imported and imported not in found:  # a name imported from a module: that module
                imported = imported.rpartition(".")[0]
            if imported and imported != name:
                targets.add(imported)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The groups of modules that import one another, round a circle (Tarjan's components)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        for target in graph.get(node, ()):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            group: list[str] = []
            while not group or group[-1] != node:
                group.append(stack.pop())
            if len(group) > 1:
                found.append(sorted(group))

    for node in graph:
        if node not in index:
            visit(node)
    return found


@pytest.mark.parametrize("package", ["cpr_kin", "planning"])
def test_no_package_has_an_import_circle(package: str) -> None:
    # at module level, inside functions and for the type checker: a circle closed only under
    # TYPE_CHECKING is still two modules that cannot be read one without the other
    assert cycles(import_graph(package)) == []
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]  # the finder finds


def test_the_robot_packages_rooms_import_downwards() -> None:
    # each sub-package of cpr_kin imports only the rooms below it: the rooms form no circle either
    graph = import_graph("cpr_kin")
    rooms = {
        room: {
            ".".join(t.split(".")[:2])
            for name, targets in graph.items()
            if within(name, room)
            for t in targets
        }
        - {room}
        for room in {".".join(name.split(".")[:2]) for name in graph if name.count(".") >= 1}
    }
    assert cycles(rooms) == []
