"""The package layout: role subpackages whose imports point one way only (read with ``ast``)."""

from __future__ import annotations

import ast
import importlib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: The subpackages of planner, lowest first: each may import only from itself and those before it.
ORDER = ["model", "world", "arm", "perception", "actions", "search", "queries", "execution", "outputs", "pipeline", "batch", "bench"]


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> list[tuple[str, int]]:
    """Every module this file imports (at any depth of the code), with the line, as absolute names."""
    name = _module_name(path)
    return _imports_of(path.read_text(), name if path.name == "__init__.py" else name.rpartition(".")[0])


def _imports_of(source: str, package: str) -> list[tuple[str, int]]:
    """The imports of ``source``, a module of ``package``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            found.append((target, node.lineno))
            # "from . import x" imports the submodule x.
            found += [(f"{target}.{alias.name}", node.lineno) for alias in node.names
                      if (ROOT / Path(*target.split("."), f"{alias.name}.py")).exists()]
    return found


def _files(package: str) -> list[Path]:
    return sorted((ROOT / package).rglob("*.py"))


def _rank(module: str) -> int | None:
    """The layer of a planner module: its subpackage's place in ORDER. The package itself, the
    public API, ranks with the benchmarks (its clients); the command line above all."""
    parts = module.split(".")
    if parts[0] != "planner":
        return None
    if len(parts) == 1:
        return ORDER.index("bench")
    return ORDER.index(parts[1]) if parts[1] in ORDER else len(ORDER)


def test_planner_has_few_top_level_modules_and_documented_role_subpackages():
    top = sorted(p.name for p in (ROOT / "planner").glob("*.py"))
    assert len(top) <= 4, top
    subpackages = sorted(p.parent.name for p in (ROOT / "planner").glob("*/__init__.py"))
    assert subpackages == sorted(ORDER)
    for name in ORDER:
        doc = importlib.import_module(f"planner.{name}").__doc__
        assert doc and "Allowed imports" in doc, name


def test_every_import_points_down():
    upward = []
    for path in _files("planner"):
        here = _rank(_module_name(path))
        for target, line in _imports(path):
            there = _rank(target)
            if there is not None and there > here:
                upward.append(f"{path.relative_to(ROOT)}:{line} imports {target}")
    assert upward == []


def test_mechanics_imports_nothing_of_the_planner():
    assert [(str(p.relative_to(ROOT)), t) for p in _files("mechanics") for t, _ in _imports(p)
            if t.split(".")[0] == "planner"] == []


@pytest.mark.parametrize("package", ["planner", "mechanics"])
def test_no_import_cycle(package):
    modules = {_module_name(p): p for p in _files(package)}
    graph = {m: {t for t, _ in _imports(p) if t in modules and t != m} for m, p in modules.items()}
    # A package's __init__ is imported with each of its modules: an edge to it is an edge to the
    # package, which re-exports what its modules define, so only module-to-module edges count.
    graph = {m: {t for t in targets if not (ROOT / Path(*t.split("."), "__init__.py")).exists()}
             for m, targets in graph.items()}
    state: dict[str, int] = {}

    def visit(m: str, trail: list[str]) -> list[str] | None:
        state[m] = 1
        for t in sorted(graph[m]):
            if state.get(t) == 1:
                return trail + [m, t]
            if t not in state and (cycle := visit(t, trail + [m])):
                return cycle
        state[m] = 2
        return None

    cycles = [c for m in sorted(graph) if m not in state and (c := visit(m, []))]
    assert cycles == []


def test_the_walker_resolves_relative_imports_at_any_depth():
    source = "import numpy\nfrom . import fields\ndef f():\n    from ..search.planning import plan\n"
    found = [t for t, _ in _imports_of(source, "planner.model")]
    assert found == ["numpy", "planner.model", "planner.model.fields", "planner.search.planning"]
    assert _rank("planner.search.planning") > _rank("planner.model.scene")  # so it is caught


#: The tests of the project as a whole (its layout, its README, its documents' references), at tests/.
PROJECT_TESTS = {"test_layout.py", "test_readme.py", "test_docs_refs.py"}


def test_the_tests_mirror_the_packages():
    """A test module lives in the folder of the package it tests (tests/mechanics/ for mechanics,
    tests/planner/<role>/ for a role package, tests/planner/ for the command), so that the tests
    of a package are found beside each other; only the project's own tests stand at tests/."""
    misplaced = []
    for path in sorted((ROOT / "tests").rglob("test_*.py")):
        folder = path.parent.relative_to(ROOT / "tests")
        if folder == Path("."):
            if path.name not in PROJECT_TESTS:
                misplaced.append(f"{path.name}: at tests/, but it tests no part of the project as a whole")
        elif not (ROOT / folder / "__init__.py").is_file():
            misplaced.append(f"{folder / path.name}: {folder} is not a package of the project")
    assert misplaced == []
    assert {p.name for p in (ROOT / "tests").glob("test_*.py")} == PROJECT_TESTS
