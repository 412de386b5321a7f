"""Choosing the method of an edge's stable region (mechanics.regions) and the modules' layering.

``mechanics.stable_region(..., method=)`` chooses procedure STABLE or the exact region; it lives
above both, so that mechanics.exact_region builds on mechanics.stable and nothing imports back.
Sources of truth: the import statements themselves (read with ``ast``, not by importing), and the
two methods' own functions.
"""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from mechanics import (DEFAULT_TIP_FACTOR, METHODS, ExactRegion, Slider, StableRegion, exact_region, procedure_stable,
                       stable_region)

MECHANICS = Path(__file__).resolve().parents[2] / "mechanics"
BLOCK = Slider([[-1, 0], [1, 0], [1, 1], [-1, 1]], cf=[0.4, 0.3])


def imports_within_mechanics() -> dict[str, set[str]]:
    """Module -> the mechanics modules it imports (relative imports), from the source."""
    graph = {}
    for path in MECHANICS.rglob("*.py"):
        parts = path.relative_to(MECHANICS).with_suffix("").parts
        name = ".".join(p for p in parts if p != "__init__")
        package = parts[:-1]  # relative imports resolve in the folder, for a package's __init__ too
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level > 0:
                base = list(package[:len(package) - (node.level - 1)])
                target = ".".join(base + ([node.module] if node.module else []))
                found |= {target} if node.module else {".".join(base + [a.name]) for a in node.names}
        graph[name] = found - {""}
    return graph


def test_mechanics_imports_have_no_cycle():
    """Depth-first search for a cycle among the package's modules (the package itself, which
    re-exports everything, left out); and the two region modules' dependency runs one way."""
    graph = imports_within_mechanics()
    graph.pop("", None)
    state: dict[str, int] = {}

    def visit(module: str, trail: list[str]) -> None:
        state[module] = 1
        for other in sorted(graph.get(module, ())):
            assert state.get(other) != 1, " -> ".join([*trail, module, other])
            if other not in state:
                visit(other, [*trail, module])
        state[module] = 2

    for module in sorted(graph):
        if module not in state:
            visit(module, [])
    assert "stable" in graph["exact_region"] and "exact_region" not in graph["stable"]
    assert {"stable", "exact_region"} <= graph["regions"]


def test_each_method_gives_its_region():
    stable = stable_region(BLOCK, 0, 0.5)
    exact = stable_region(BLOCK, 0, 0.5, method="exact")
    assert METHODS == ("stable", "exact")
    assert type(stable) is StableRegion and type(exact) is ExactRegion
    np.testing.assert_array_equal(stable.rows[1], procedure_stable(BLOCK, 0, 0.5).rows[1])
    assert exact.polygon.equals(exact_region(BLOCK, 0, 0.5).polygon)
    loose = stable_region(BLOCK, 0, 0.5, tip_factor=1.0)
    assert loose.cor_vertices(1).tolist() != stable.cor_vertices(1).tolist()  # the factor reaches STABLE
    robust = stable_region(BLOCK, 0, 0.5, method="exact", cf_radius=0.05)
    assert robust.cf_radius == 0.05 and robust.polygon.area < exact.polygon.area


@pytest.mark.parametrize("kwargs, message", [
    ({"method": "approximate"}, "method must be one of 'stable', 'exact'"),
    ({"method": "stable", "cf_radius": 0.05}, "assumes a known CF"),
    ({"method": "exact", "tip_factor": 1.0}, "tip_factor is procedure STABLE's"),
])
def test_options_a_method_cannot_take_are_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        stable_region(BLOCK, 0, 0.5, **kwargs)
    assert stable_region(BLOCK, 0, 0.5, method="exact", tip_factor=DEFAULT_TIP_FACTOR).polygon.area > 0
