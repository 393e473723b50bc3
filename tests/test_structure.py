"""The house: the import graph of ``snapping.simulate`` has no circle, and its data flow one way.

Every ``import`` statement of ``src/snapping/simulate/**.py`` is read with :mod:`ast`, at
module level **and** inside functions (a deferred import is still a dependency: it only
moves the circle from import time to call time). Within the package the graph must have
no cycle, and the stages of its data flow, problem -> options -> methods -> driver ->
dataset, must depend one way: a stage reaches (directly or through other modules) only
stages before it, except that the driver, which joins them, writes the dataset. The
dataset may know the problem (it records it and reads it back), never the options, the
methods or the driver. ``if TYPE_CHECKING:`` blocks do not run and are not counted.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parent.parent / "src"
PKG = "snapping.simulate"

#: the simulator's data flow: each may import those before it, never those after it
FLOW = ("snapping.simulate.problem", "snapping.simulate.options", "snapping.simulate.methods",
        "snapping.simulate.driver", "snapping.simulate.dataset")


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _modules(package: str) -> dict[str, Path]:
    root = SRC.joinpath(*package.split("."))
    return {_module_name(p): p for p in sorted(root.rglob("*.py"))}


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _imports(tree: ast.AST):
    """Every import node of ``tree`` (at any depth), except under ``if TYPE_CHECKING:``."""
    stack = [tree]
    while stack:
        node = stack.pop()
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        stack.extend(ast.iter_child_nodes(node))


def import_graph(package: str = PKG) -> dict[str, set[str]]:
    """{module: modules of ``package`` it imports}, module-level and function-level imports
    alike. ``from . import x`` counts as an import of ``x`` (the package itself is already
    being imported); ``from .m import name`` as one of ``m`` (and of ``m.name`` if that is a
    module)."""
    mods = _modules(package)
    graph = {m: set() for m in mods}
    for m, path in mods.items():
        here = m if path.name == "__init__.py" else m.rsplit(".", 1)[0]
        for node in _imports(ast.parse(path.read_text(), str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif node.level == 0:
                targets = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
            else:
                base = here.split(".")[: len(here.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
                subs = [f"{mod}.{a.name}" for a in node.names if f"{mod}.{a.name}" in mods]
                targets = subs + ([mod] if node.module or len(subs) < len(node.names) else [])
            graph[m].update(t for t in targets if t in mods and t != m)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as [a, b, ..., a], or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(m):
        state[m] = 1
        path.append(m)
        for n in sorted(graph.get(m, ())):
            if state.get(n) == 1:
                return path[path.index(n):] + [n]
            if n not in state:
                found = visit(n)
                if found:
                    return found
        state[m] = 2
        path.pop()
        return None

    for m in sorted(graph):
        if m not in state:
            found = visit(m)
            if found:
                return found
    return None


def reaches(graph: dict[str, set[str]], start: str) -> set[str]:
    """Every module ``start`` imports, directly or through others."""
    seen, todo = set(), [start]
    while todo:
        for n in graph.get(todo.pop(), ()):
            if n not in seen:
                seen.add(n)
                todo.append(n)
    return seen


def _in(module: str, unit: str) -> bool:
    return module == unit or module.startswith(unit + ".")


def test_the_graph_is_read():
    """The reader sees the imports it must see (a broken reader would pass everything)."""
    g = import_graph()
    assert "snapping.simulate.kernels" in g["snapping.simulate.options"]  # from . import kernels as K
    assert "snapping.simulate.dataset" in g["snapping.simulate.driver"]  # from .dataset import Run, ...
    assert "snapping.simulate.problem" in g["snapping.simulate.dataset"]  # inside problem_from_dataset
    assert "snapping.simulate.methods.dop853" in g["snapping.simulate.ensemble"]  # from .methods import dop853
    assert "snapping.simulate.methods" in g["snapping.simulate.driver"]  # from . import methods as M
    assert "snapping.simulate" not in g["snapping.simulate.options"]  # the package itself is not an edge
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": set()}) is None


def test_no_import_circle_in_simulate():
    cycle = find_cycle(import_graph())
    assert cycle is None, "import circle in snapping.simulate: " + " -> ".join(cycle)


#: the stages a stage may reach besides those before it on FLOW
EXTRA = {"snapping.simulate.driver": ("snapping.simulate.dataset",)}


@pytest.mark.parametrize("unit", FLOW)
def test_data_flow_one_way(unit):
    g = import_graph()
    i = FLOW.index(unit)
    allowed = FLOW[:i] + EXTRA.get(unit, ())
    barred = [u for u in FLOW if u != unit and u not in allowed]
    mine = [m for m in g if _in(m, unit)]
    bad = sorted({(m, n) for m in mine for n in reaches(g, m) for u in barred if _in(n, u)})
    assert not bad, (f"{unit} reaches stages after it on the data flow {' -> '.join(FLOW)} "
                     f"(module, what it reaches): {bad}")
