"""The package's imports point one way, and no module reaches into another's privates.

Both rules are read from the source with :mod:`ast`; nothing of ``petriflow`` is
imported, so a cycle that only bites at run time (an import inside a function, one
under ``if TYPE_CHECKING:``) counts as much as one at the top of a module.

**Edges.** Every ``import`` statement of a module under ``petriflow/``, wherever it
stands, draws an edge from that module to the module it names: ``import a.b`` and
``from a import b`` lead to ``a.b`` where ``a/b.py`` (or ``a/b/__init__.py``) exists,
otherwise to ``a`` (its ``__init__.py``). Relative imports are resolved against the
importing module's package. The implicit loading of parent packages is not an edge
(every submodule would otherwise sit in a circle with its package's ``__init__``).

**Cycles** are the strongly connected components of more than one module (or a
module importing itself).

**Private use** is any of:

* ``from M import _name``, or ``M._name`` read from a module bound by ``import M``,
  where ``M`` is another module of ``petriflow``: a name with one leading underscore
  belongs to the module that defines it;
* ``obj._name`` (``obj`` not ``self`` or ``cls``) where ``_name`` is defined (a
  function, method, class, or assigned name or attribute) in another module of
  ``petriflow`` and nowhere in this one: another module's private member reached
  through one of its objects;
* importing a private module (a path part with a leading underscore, such as
  ``analysis/_graph.py``) from outside the package that holds it: it belongs to that
  package (the package's own modules, its ``__init__`` included, may use it; that is
  how a package hands on what its private modules define).

A package's ``__init__`` re-exporting its modules' public names is not private use,
and neither is a module using its own private names. Dunder names (``__version__``,
``__all__``) are not private.

``python tests/test_architecture.py`` prints the cycles and private imports found,
with their counts, allowlisted or not.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGE = "petriflow"

# Nothing is allowlisted: petriflow/runtime/ is untied too (issue 45's runtime branch), so the
# tests below hold the whole package to the rules. An entry added here is a debt to name.
RUNTIME_CYCLES_PENDING: set[frozenset[str]] = set()
RUNTIME_PRIVATE_PENDING: set[str] = set()  # "importer <- module that defines it: name"


def module_files(root: Path = ROOT) -> dict[str, Path]:
    """Every module of the package, by dotted name (a package by its own name)."""
    modules = {}
    for path in sorted((root / PACKAGE).rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = path
    return modules


def _is_package(name: str, modules: dict[str, Path]) -> bool:
    return modules[name].name == "__init__.py"


def _absolute(node: ast.ImportFrom, importer: str, modules: dict[str, Path]) -> str:
    """The dotted module that ``from ... import`` names, relative levels resolved."""
    if not node.level:
        return node.module or ""
    package = importer if _is_package(importer, modules) else importer.rpartition(".")[0]
    for _ in range(node.level - 1):
        package = package.rpartition(".")[0]
    return f"{package}.{node.module}" if node.module else package


def imports(importer: str, tree: ast.AST, modules: dict[str, Path]) -> Iterator[tuple[str, str]]:
    """``(imported module, name or "")`` for every import statement in ``tree``.

    The name is what ``from M import name`` takes from ``M`` when ``M.name`` is not
    itself a module; plain ``import M`` and submodule imports give ``""``.
    """
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                name = alias.name
                while name and name not in modules:
                    name = name.rpartition(".")[0]
                if name:
                    yield name, ""
        elif isinstance(node, ast.ImportFrom):
            source = _absolute(node, importer, modules)
            if source.split(".")[0] != PACKAGE:
                continue
            for alias in node.names:
                submodule = f"{source}.{alias.name}"
                if submodule in modules:
                    yield submodule, ""
                elif source in modules:
                    yield source, alias.name


def module_aliases(importer: str, tree: ast.AST, modules: dict[str, Path]) -> dict[str, str]:
    """Local names bound to a petriflow module (``import a.b as m``, ``from a import b``)."""
    aliases = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname and alias.name in modules:
                    aliases[alias.asname] = alias.name
        elif isinstance(node, ast.ImportFrom):
            source = _absolute(node, importer, modules)
            for alias in node.names:
                if f"{source}.{alias.name}" in modules:
                    aliases[alias.asname or alias.name] = f"{source}.{alias.name}"
    return aliases


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__")


def _owner_of_private_module(module: str) -> str | None:
    """The package a private module belongs to (``a.b`` for ``a.b._c.d``), or None."""
    parts = module.split(".")
    for index, part in enumerate(parts):
        if _private(part):
            return ".".join(parts[:index])
    return None


def _inside(importer: str, package: str) -> bool:
    return importer == package or importer.startswith(package + ".")


def private_members(tree: ast.AST) -> set[str]:
    """The private names a module defines: functions, methods, classes, assigned names
    and attributes."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            names.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store):
            names.add(node.attr)
    return {name for name in names if _private(name)}


def scan(root: Path = ROOT) -> tuple[dict[str, set[str]], set[tuple[str, str, str]]]:
    """The import graph of the package and its private uses across modules."""
    modules = module_files(root)
    trees = {name: ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
             for name, path in modules.items()}
    members = {name: private_members(tree) for name, tree in trees.items()}
    graph: dict[str, set[str]] = {name: set() for name in modules}
    private: set[tuple[str, str, str]] = set()
    for importer, tree in trees.items():
        for imported, name in imports(importer, tree, modules):
            graph[importer].add(imported)
            if imported == importer:
                continue
            owner = _owner_of_private_module(imported)
            if owner is not None and not _inside(importer, owner):
                private.add((importer, imported, name or imported.rpartition(".")[2]))
            if _private(name):
                private.add((importer, imported, name))
        aliases = module_aliases(importer, tree, modules)
        for node in ast.walk(tree):
            if not (isinstance(node, ast.Attribute) and _private(node.attr)):
                continue
            owner = node.value.id if isinstance(node.value, ast.Name) else None
            if owner in aliases:
                if aliases[owner] != importer:
                    private.add((importer, aliases[owner], node.attr))
            elif owner not in ("self", "cls") and node.attr not in members[importer]:
                for other in sorted(m for m, names in members.items() if node.attr in names):
                    private.add((importer, other, node.attr))
    return graph, private


def described(use: tuple[str, str, str]) -> str:
    """A private use as the allowlist and the script write it."""
    importer, owner, name = use
    return f"{importer} <- {owner}: {name}"


def cycles(graph: dict[str, set[str]]) -> list[frozenset[str]]:
    """The strongly connected components that are cycles (Tarjan, iteratively)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    found: list[frozenset[str]] = []
    counter = 0
    for start in sorted(graph):
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = counter
        counter += 1
        stack.append(start)
        on_stack.add(start)
        while work:
            node, successors = work[-1]
            for successor in successors:
                if successor not in index:
                    index[successor] = low[successor] = counter
                    counter += 1
                    stack.append(successor)
                    on_stack.add(successor)
                    work.append((successor, iter(sorted(graph[successor]))))
                    break
                if successor in on_stack:
                    low[node] = min(low[node], index[successor])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = set()
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.add(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in graph[node]:
                        found.append(frozenset(component))
    return found


def test_cycles_and_private_uses_are_found_in_a_small_tree(tmp_path):
    """The scan sees a cycle closed by an import inside a function, and each kind of
    private use: a name imported, read off a module, reached through an object, and a
    private module imported from outside its package."""
    package = tmp_path / PACKAGE
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "sub" / "__init__.py").write_text("from ._hidden import shown\n")
    (package / "sub" / "_hidden.py").write_text("shown = 1\n")
    (package / "a.py").write_text("from petriflow import b\n")
    (package / "b.py").write_text("def late():\n    from .a import _secret\n")
    (package / "c.py").write_text("import petriflow.a as a\nfrom petriflow.sub._hidden import shown\nx = a._y\n"
                                  "def use(thing):\n    return thing._counter, thing._own\n"
                                  "_own = 1\n")
    (package / "d.py").write_text("class Counter:\n    def __init__(self):\n        self._counter = 0\n")
    graph, private = scan(tmp_path)
    assert cycles(graph) == [frozenset({"petriflow.a", "petriflow.b"})]
    assert private == {
        ("petriflow.b", "petriflow.a", "_secret"),
        ("petriflow.c", "petriflow.a", "_y"),
        ("petriflow.c", "petriflow.d", "_counter"),
        ("petriflow.c", "petriflow.sub._hidden", "shown"),
    }


def test_no_import_cycle_in_the_package():
    """No module of petriflow/ imports itself back, at any depth, through any import."""
    found = set(cycles(scan()[0]))
    assert found - RUNTIME_CYCLES_PENDING == set()
    assert RUNTIME_CYCLES_PENDING - found == set(), "an allowlisted cycle is gone: remove it"


def test_no_private_name_imported_across_modules():
    """No module of petriflow/ takes a private name from another (rule in the module text)."""
    found = {described(use) for use in scan()[1]}
    assert found - RUNTIME_PRIVATE_PENDING == set()
    assert RUNTIME_PRIVATE_PENDING - found == set(), "an allowlisted use is gone: remove it"


if __name__ == "__main__":
    graph, private = scan()
    found = cycles(graph)
    print(f"{len(found)} import cycles ({len(set(found) & RUNTIME_CYCLES_PENDING)} allowlisted)")
    for component in sorted(found, key=lambda c: (-len(c), sorted(c))):
        mark = " (allowlisted)" if component in RUNTIME_CYCLES_PENDING else ""
        print(f"  {len(component)}: {', '.join(sorted(component))}{mark}")
    uses = sorted(described(use) for use in private)
    allowed = len(set(uses) & RUNTIME_PRIVATE_PENDING)
    print(f"{len(uses)} private uses across modules ({allowed} allowlisted)")
    for use in uses:
        print(f"  {use}{' (allowlisted)' if use in RUNTIME_PRIVATE_PENDING else ''}")
