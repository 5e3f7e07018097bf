"""The runtime's imports point one way: no cycle, no private name taken across modules."""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import petriflow

ROOT = Path(petriflow.__file__).resolve().parent
RUNTIME = "petriflow.runtime"


def modules() -> dict[str, Path]:
    """``{dotted name: file}`` of every module of the petriflow package."""
    found = {}
    for file in ROOT.rglob("*.py"):
        parts = ("petriflow", *file.relative_to(ROOT).with_suffix("").parts)
        found[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = file
    return found


def imports(name: str, file: Path, known: dict[str, Path]) -> list[tuple[str, str | None]]:
    """``(module imported, name taken or None)`` for every import of ``file``, those inside
    functions and under ``TYPE_CHECKING`` included."""
    package = name if file.name == "__init__.py" else name.rpartition(".")[0]
    out: list[tuple[str, str | None]] = []
    for node in ast.walk(ast.parse(file.read_text())):
        if isinstance(node, ast.Import):
            out.extend((alias.name, None) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, *([node.module] if node.module else [])])
            for alias in node.names:
                full = f"{base}.{alias.name}"
                out.append((full, None) if full in known else (base, alias.name))
    return out


def owner(name: str, known: dict[str, Path]) -> str | None:
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


@functools.lru_cache(maxsize=1)
def graph() -> tuple[dict[str, set[str]], list[tuple[str, str, str]]]:
    """The import graph of petriflow's modules, and ``(importer, module, private name)``."""
    known = modules()
    edges: dict[str, set[str]] = {name: set() for name in known}
    private = []
    for name, file in known.items():
        for target, taken in imports(name, file, known):
            module = owner(target, known)
            if module is None or module == name:
                continue
            edges[name].add(module)
            if taken is not None and taken.startswith("_") and not taken.startswith("__"):
                private.append((name, module, taken))
    return edges, private


def cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in edges[node]:
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                top = stack.pop()
                on_stack.discard(top)
                component.append(top)
                if top == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in edges:
        if node not in index:
            visit(node)
    return found


def test_a_loop_of_imports_is_found():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_import_cycle_inside_the_runtime():
    """Counting imports inside functions and under TYPE_CHECKING too."""
    edges, _ = graph()
    inside = {name: {t for t in targets if t.startswith(RUNTIME)} for name, targets in edges.items()
              if name.startswith(RUNTIME)}
    assert cycles(inside) == []


def test_no_cycle_passes_through_the_runtime():
    edges, _ = graph()
    assert [c for c in cycles(edges) if any(name.startswith(RUNTIME) for name in c)] == []


def test_no_private_name_is_imported_from_or_into_the_runtime():
    _, private = graph()
    assert [p for p in private if p[0].startswith(RUNTIME) or p[1].startswith(RUNTIME)] == []
