"""The actions and guards a user's action module declares, read from its source without
running it.

Looking at a net (``petriflow info``, ``check``) never imports the action modules its
run configuration names (docs/security.md). It reads them instead: each module's file
is found as an import would find it (nothing is imported, not even a parent package),
parsed with :mod:`ast`, and its registrations are collected:

* ``@action("name", params={...})`` on a function, ``@action("name")`` on an
  :class:`~petriflow.runtime.action.Action` subclass (its ``params``, ``requires``,
  ``resources`` class attributes, inherited from classes of the module or of
  petriflow), ``registry.register("name", Class)``, ``registry.action("name", ...)``
  as a decorator or called on a function;
* ``@guard("name", reads=[...])``, ``registry.predicate("name", ...)``;
* ``register_state("name", ...)`` and ``register_resource("name", ...)`` (names only).

A parameter is known when it is written ``Param(...)`` or ``Port(...)`` with literal
arguments: its type a builtin type name (``float``, ``int``, ``str``, ``bool``,
``list``, ``dict``...), ``None``, a tuple of those, or a class imported from
petriflow; module-level constants (``MINUTES = 5.0``) count as literals. Modules the
read module imports from its own folder (or package) are read too.

Whatever cannot be known without running the code is kept as a *gap* with its reason,
never guessed: an action name that is not a literal, a ``params`` that is not a
literal dict, a type that is not a literal name, a base class from elsewhere, an
overridden ``check_params``, a module not found or not parsed, an import of a module
that is not read. :func:`petriflow.runtime.binding.bind` checks a net against these
declarations with the same code (and so the same messages) as a run, and lists the
gaps as not checked.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "mycharger.py").write_text('''
    ... from petriflow import Param, action
    ... raise SystemExit("never imported")
    ... @action("mycharger.charge", params={"minutes": Param(float, 5.0, low=0)})
    ... def charge(ctx):
    ...     yield ctx.params["minutes"] * 60
    ... ''')
    >>> found = read_declarations([str(folder / "mycharger.py")])
    >>> declared = found.actions["mycharger.charge"]
    >>> declared.where, declared.params["minutes"].type, declared.gaps
    ('mycharger.py:4', <class 'float'>, [])
    >>> declared.action_class().check_params({"minuts": 2}, where="dock")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: 'dock': action has no parameter 'minuts' (did you mean 'minutes'?) (it takes: minutes)
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import sys
from collections.abc import Iterable
from dataclasses import dataclass, field
from importlib.machinery import PathFinder
from pathlib import Path
from typing import Any

from petriflow.runtime.action import REQUIRED, Action, ActionFailure, Param, Port, type_names

__all__ = ["ActionDeclaration", "Declarations", "GuardDeclaration", "find_source", "read_declarations"]

#: The most files one reading follows (a module and the local modules it imports).
MAX_FILES = 200
#: The largest source file read, in bytes.
MAX_BYTES = 4_000_000

#: Builtin type names a parameter's type may be written as.
_BUILTIN_TYPES: dict[str, type] = {t.__name__: t for t in (
    float, int, str, bool, list, dict, tuple, set, frozenset, bytes, complex, object)}
_PARAM_FIELDS = ("type", "default", "doc", "choices", "low", "high", "places")
_UNKNOWN = object()  # an expression whose value cannot be known without running code


@dataclass
class ActionDeclaration:
    """An action a module's source declares.

    Attributes:
        name: the registered name.
        where: ``file:line`` of the registration.
        params: ``{name: Param}`` as declared, or ``None`` when not a literal.
        requires: what a transition bound to it must have (see ``Action.requires``).
        resources: ``{local name: resource type}`` it declares.
        base: the petriflow :class:`Action` class it derives from (its own checks apply).
        gaps: what of it cannot be checked without running the module, each a reason.
    """

    name: str
    where: str
    params: dict[str, Param] | None = field(default_factory=dict)
    requires: frozenset[str] = frozenset()
    resources: dict[str, str] = field(default_factory=dict)
    base: type[Action] = Action
    gaps: list[str] = field(default_factory=list)

    def action_class(self) -> type[Action]:
        """A stand-in :class:`Action` class with the declared ``params``, ``requires`` and
        ``resources`` (and the petriflow base class's checks), so binding checks a net
        against the declaration with the code a run uses. It cannot run: its hooks fail,
        saying that the module was not imported."""
        return type(f"Declared<{self.name}>", (_Declared, self.base), {
            "__module__": __name__, "__doc__": f"{self.name}, declared at {self.where} (not imported)",
            "params": dict(self.params or {}), "requires": frozenset(self.requires),
            "resources": dict(self.resources), "agent_state": None, "declaration": self})


class _Declared(Action):
    """Base of the stand-ins :meth:`ActionDeclaration.action_class` makes."""

    declaration: ActionDeclaration

    def _refuse(self, *args: Any) -> None:
        raise ActionFailure(f"action {self.declaration.name!r} was checked from its source"
                            f" ({self.declaration.where}) without importing it: import its module to run it")

    setup = start = _refuse  # nothing of it can run


@dataclass
class GuardDeclaration:
    """A guard a module's source declares: its name, ``file:line``, the agent-state keys
    it reads (``None``: it reads tokens) and what cannot be known (``gaps``)."""

    name: str
    where: str
    reads: tuple[str, ...] | None = None
    gaps: list[str] = field(default_factory=list)

    def __call__(self, *args: Any) -> bool:
        raise ActionFailure(f"guard {self.name!r} was checked from its source ({self.where}) without"
                            " importing it: import its module to evaluate it")


@dataclass
class Declarations:
    """What the action modules declare, read from their source.

    Attributes:
        actions: ``{name: ActionDeclaration}``.
        guards: ``{name: GuardDeclaration}``.
        states: ``{agent-state type name: file:line}`` (``register_state``).
        resources: ``{resource type name: file:line}`` (``register_resource``).
        hidden: ``{kind: [(prefix, reason), ...]}``: why more names of that kind
            (``action``, ``guard``, ``agent state``, ``resource``) starting with ``prefix``
            may be declared than were read: a name that is not a literal (``f"shop.{n}"``:
            prefix ``shop.``). ``"*"``: for every kind (a module not found or not parsed).
        unread: ``[reason, ...]``: modules imported but not read (neither beside the
            module nor the standard library nor petriflow): they may register names too.
        files: the files read.
    """

    actions: dict[str, ActionDeclaration] = field(default_factory=dict)
    guards: dict[str, GuardDeclaration] = field(default_factory=dict)
    states: dict[str, str] = field(default_factory=dict)
    resources: dict[str, str] = field(default_factory=dict)
    hidden: dict[str, list[tuple[str, str]]] = field(default_factory=dict)
    unread: list[str] = field(default_factory=list)
    files: list[str] = field(default_factory=list)

    def names(self, kind: str) -> dict[str, Any]:
        """The declared names of ``kind`` (``action``, ``guard``, ``agent state``, ``resource``)."""
        return {"action": self.actions, "guard": self.guards, "agent state": self.states,
                "resource": self.resources}[kind]

    def namespaces(self) -> set[str]:
        """The namespaces (``ns`` of ``ns.name``) of every name declared literally."""
        return {name.partition(".")[0] for kind in ("action", "guard", "agent state", "resource")
                for name in self.names(kind) if "." in name}

    def missing(self, kind: str, name: str) -> str | None:
        """Why ``name`` of ``kind``, declared by none of the modules read, may still be
        declared by them (a reason for listing it as not checked), or ``None``: it is not
        (what the modules declare was all read)."""
        reasons = [why for prefix, why in self.hidden.get("*", []) + self.hidden.get(kind, [])
                   if name.startswith(prefix)]
        if reasons:
            return "; ".join(_capped(reasons))
        if "." in name and name.partition(".")[0] in self.namespaces():
            return None  # a module declares that namespace, and everything it declares was read
        if self.unread:
            return f"no module read declares it, but {'; '.join(_capped(self.unread))}"
        return None

    def put(self, kind: str, name: str, found: Any) -> None:
        """Record ``found`` as ``name`` of ``kind`` (a name declared twice keeps a gap)."""
        mine = self.names(kind)
        mine[name] = _twice(mine[name], found) if name in mine else found

    def add(self, other: Declarations) -> None:
        for kind in ("action", "guard", "agent state", "resource"):
            for name, found in other.names(kind).items():
                self.put(kind, name, found)
        for kind, reasons in other.hidden.items():
            self.hidden.setdefault(kind, []).extend(reasons)
        self.unread.extend(other.unread)
        self.files.extend(other.files)


def _capped(reasons: list[str], most: int = 3) -> list[str]:
    unique = list(dict.fromkeys(reasons))
    return unique[:most] + ([f"{len(unique) - most} more"] if len(unique) > most else [])


def _twice(first: Any, second: Any) -> Any:
    """One name declared twice: which one a run binds depends on the code that runs."""
    if isinstance(first, str):
        return first
    again = f"it is declared more than once ({first.where}, {second.where}): which one a run binds is not known"
    if isinstance(first, ActionDeclaration):
        return ActionDeclaration(first.name, first.where, None, gaps=[again])
    return GuardDeclaration(first.name, first.where, None, [again])


def find_source(entry: str) -> tuple[Path | None, str]:
    """The source file of an action module entry as a run configuration stores it (an
    absolute ``.py`` path, a package folder, or a module name), found without importing
    anything; ``(None, why)`` when there is none to read.

    A module name is looked up on ``sys.path`` as an import would, one dotted part at a
    time, without running any package's ``__init__``.
    """
    path = Path(entry)
    if entry.endswith(".py") or path.is_absolute():
        file = path if entry.endswith(".py") else path / "__init__.py"
        if file.is_file():
            return file, ""
        return None, f"action module {entry!r} was not found"
    spec, locations = None, list(sys.path)
    parts = entry.split(".")
    for i in range(len(parts)):
        name = ".".join(parts[:i + 1])
        try:
            spec = PathFinder.find_spec(name, locations)
        except (ImportError, ValueError, OSError) as exc:
            return None, f"action module {entry!r} cannot be looked up: {exc}"
        if spec is None:
            return None, f"action module {entry!r} was not found on the import path"
        locations = list(spec.submodule_search_locations or [])
    origin = spec.origin if spec is not None else None
    if not origin or not origin.endswith(".py") or not Path(origin).is_file():
        return None, f"action module {entry!r} has no Python source to read ({origin or 'a namespace package'})"
    return Path(origin), ""


def read_declarations(entries: Iterable[str]) -> Declarations:
    """What the action modules ``entries`` (as :attr:`RunConfig.actions` stores them)
    declare, read from their source and the local modules they import; nothing is run."""
    found = Declarations()
    seen: set[Path] = set()
    for entry in entries:
        file, why = find_source(entry)
        if file is None:
            found.hidden.setdefault("*", []).append(("", why))
            continue
        # what an import of it puts on the path: a file's folder, a package's parent
        root, top = file.parent.parent if file.name == "__init__.py" else file.parent, None
        if not (entry.endswith(".py") or Path(entry).is_absolute()):
            # a module found on the import path: only its own package is read with it
            root = file.parents[entry.count(".") + (1 if file.name == "__init__.py" else 0)]
            top = entry.partition(".")[0]
        queue = [file]
        while queue:
            file = queue.pop(0)
            if file in seen:
                continue
            seen.add(file)
            if len(seen) > MAX_FILES:
                found.hidden.setdefault("*", []).append(("", (f"the action modules import more than {MAX_FILES}"
                                                               " local modules; the rest are not read")))
                break
            reader = _Reader(file, root, top)
            found.add(reader.read())
            queue.extend(reader.local_imports)
    return found


class _Reader:
    """Reads one source file's declarations (see the module's docstring)."""

    def __init__(self, file: Path, root: Path, top: str | None = None) -> None:
        self.file, self.root, self.top = file, root, top
        self.label = file.name if file.name != "__init__.py" else f"{file.parent.name}/__init__.py"
        self.found = Declarations(files=[str(file)])
        self.local_imports: list[Path] = []
        self.aliases: dict[str, tuple[str, str]] = {}  # local name -> (module, attribute or "")
        self.constants: dict[str, ast.expr] = {}
        self.classes: dict[str, list[ast.ClassDef]] = {}
        self.handled: set[int] = set()
        self.resolving: set[int] = set()  # the classes being read (a class naming itself)
        self.star = False  # a ``from ... import *``: an unbound name may be petriflow's

    def at(self, node: ast.AST) -> str:
        return f"{self.label}:{getattr(node, 'lineno', '?')}"

    # Reading ------------------------------------------------------------------------
    def read(self) -> Declarations:
        try:
            if self.file.stat().st_size > MAX_BYTES:
                raise ValueError(f"larger than {MAX_BYTES:,} bytes")
            source = importlib.util.decode_source(self.file.read_bytes())
            tree = ast.parse(source, filename=str(self.file))
        except SyntaxError as exc:
            return self.unreadable(f"{self.label}:{exc.lineno or '?'} cannot be parsed ({exc.msg})")
        except (OSError, ValueError, UnicodeDecodeError, RecursionError, MemoryError) as exc:
            return self.unreadable(f"{self.label} cannot be read ({type(exc).__name__}: {exc})")
        try:
            self.scan(tree)
        except RecursionError:
            return self.unreadable(f"{self.label} is nested too deeply to read")
        return self.found

    def unreadable(self, why: str) -> Declarations:
        self.found.hidden.setdefault("*", []).append(("", why))
        return self.found

    def scan(self, tree: ast.Module) -> None:
        body = [n for n in tree.body if not _is_main_guard(n)]
        assigned: dict[str, int] = {}
        for node in ast.walk(ast.Module(body=body, type_ignores=[])):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                self.imports(node)
            elif isinstance(node, ast.ClassDef):
                self.classes.setdefault(node.name, []).append(node)
            elif isinstance(node, ast.Call) and _callee(node) in ("import_module", "__import__"):
                self.found.unread.append(f"{self.at(node)} imports a module by a computed name, which is not read")
        for node in ast.walk(tree):  # every name bound anywhere (a local of the same name too: no guess)
            if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
                assigned[node.id] = assigned.get(node.id, 0) + 1
            elif isinstance(node, (ast.Global, ast.Nonlocal)):
                for name in node.names:
                    assigned[name] = assigned.get(name, 0) + 2
        for node in body:  # module-level constants: a name bound once, at module level
            targets = node.targets if isinstance(node, ast.Assign) else [node.target] \
                if isinstance(node, ast.AnnAssign) else []
            if _node_value(node) is not None and len(targets) == 1 and isinstance(targets[0], ast.Name):
                self.constants[targets[0].id] = _node_value(node)
        self.constants = {k: v for k, v in self.constants.items() if assigned.get(k) == 1}
        nodes = list(ast.walk(ast.Module(body=body, type_ignores=[])))
        for node in nodes:  # decorators first, so their calls are not counted again
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
                for decorator in node.decorator_list:
                    if isinstance(decorator, ast.Call) and self.kind(decorator) in ("action", "guard"):
                        self.handled.add(id(decorator))
                        self.registration(decorator, node)
        for node in nodes:  # registry.action("n")(f), registry.predicate("n")(f)
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Call) \
                    and self.kind(node.func) in ("action", "guard") and id(node.func) not in self.handled:
                self.handled.add(id(node.func))
                self.registration(node.func, node.args[0] if len(node.args) == 1 else None)
        for node in nodes:
            if isinstance(node, ast.Call) and id(node) not in self.handled:
                kind = self.kind(node)
                if kind in ("action", "guard"):  # a decorator kept aside: its target is not known
                    self.registration(node, None)
                elif kind == "register":
                    target = node.args[1] if len(node.args) > 1 else _keyword(node, "target")
                    self.registration(node, target)
                elif kind in ("agent state", "resource"):
                    name = self.value(node.args[0]) if node.args else _UNKNOWN
                    if isinstance(name, str):
                        self.found.names(kind).setdefault(name, self.at(node))
                    else:
                        self.hidden(kind, node, node.args[0] if node.args else None)

    def hidden(self, kind: str, node: ast.AST, name: ast.expr | None) -> None:
        """A registration whose name is not a literal: names of ``kind`` starting as it
        does (its literal start, if any) may be declared unseen."""
        prefix = self.prefix(name)
        self.found.hidden.setdefault(kind, []).append((prefix, (
            f"{self.at(node)} registers {'an' if kind[0] in 'aeiou' else 'a'} {kind} whose name is not a literal"
            + (f" (it starts {prefix!r})" if prefix else ""))))

    def prefix(self, node: ast.expr | None) -> str:
        """The literal start of a string expression (``f"shop.{n}"``: ``shop.``)."""
        if isinstance(node, ast.JoinedStr):
            start = ""
            for part in node.values:
                item = self.value(part.value if isinstance(part, ast.FormattedValue) and part.conversion == -1
                                  and part.format_spec is None else part)
                if not isinstance(item, str):
                    break
                start += item
            return start
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            left = self.value(node.left)
            return left + self.prefix(node.right) if isinstance(left, str) else self.prefix(node.left)
        return ""

    # Imports ------------------------------------------------------------------------
    def imports(self, node: ast.Import | ast.ImportFrom) -> None:
        if isinstance(node, ast.Import):
            for alias in node.names:
                self.aliases[alias.asname or alias.name.partition(".")[0]] = \
                    (alias.name if alias.asname else alias.name.partition(".")[0], "")
                self.follow(alias.name, node)
            return
        if node.level:
            package = self.file.parent
            for _ in range(node.level - 1):
                package = package.parent
            base = package.joinpath(*node.module.split(".")) if node.module else package
            for alias in node.names:
                if alias.name == "*":
                    self.star = True
                    continue
                self.aliases[alias.asname or alias.name] = (f"{'.' * node.level}{node.module or ''}", alias.name)
            targets = [base] if node.module else []
            targets += [base / alias.name for alias in node.names if alias.name != "*"]
            found = [f for f in (_module_file(t) for t in targets) if f is not None]
            self.local_imports.extend(found)
            if node.module and not found:
                self.found.unread.append(f"{self.at(node)} imports '{'.' * node.level}{node.module}', which is"
                                         " not found")
            return
        module = node.module or ""
        for alias in node.names:
            if alias.name == "*":
                self.star = True
                continue
            self.aliases[alias.asname or alias.name] = (module, alias.name)
        if not module or not self.follow(module, node):
            return
        for alias in node.names:  # from pkg import submodule
            file = _module_file(self.root.joinpath(*module.split("."), alias.name))
            if file is not None:
                self.local_imports.append(file)

    def follow(self, module: str, node: ast.AST) -> bool:
        """Queue the local module ``module`` for reading; note one that is not read."""
        top = module.partition(".")[0]
        if top in sys.stdlib_module_names or top in ("petriflow", "__future__"):
            return False
        file = None if self.top not in (None, top) else _module_file(self.root.joinpath(*module.split(".")))
        if file is None:
            self.found.unread.append(f"{self.at(node)} imports {module!r}, which is not read")
            return False
        self.local_imports.append(file)
        return True

    def petriflow_object(self, node: ast.expr) -> Any:
        """The petriflow object (a class, ``REQUIRED``) ``node`` names through the module's
        imports, or ``_UNKNOWN``. petriflow's own modules are trusted installed code."""
        path = []
        while isinstance(node, ast.Attribute):
            path.insert(0, node.attr)
            node = node.value
        if not isinstance(node, ast.Name):
            return _UNKNOWN
        module, attribute = self.aliases.get(node.id, ("petriflow", node.id) if self.star else ("", ""))
        if module != "petriflow" and not module.startswith("petriflow."):
            return _UNKNOWN
        try:
            found = importlib.import_module(module)
            for step in ([attribute] if attribute else []) + path:
                found = getattr(found, step)
        except (ImportError, AttributeError):
            return _UNKNOWN
        return found

    def kind(self, call: ast.Call) -> str | None:
        """What registering ``call`` is, if any: ``action``, ``guard``, ``register`` (an
        action class), ``agent state``, ``resource``."""
        func = call.func
        if isinstance(func, ast.Name):  # petriflow's action/guard, or a helper of that name (read alike)
            attribute = self.aliases.get(func.id, ("", func.id))[1] or func.id
            return {"action": "action", "guard": "guard"}.get(attribute)
        if not isinstance(func, ast.Attribute):
            return None
        receiver = func.value
        if isinstance(receiver, ast.Name) and receiver.id in self.aliases:
            module = self.aliases[receiver.id][0]
            if not (module == "petriflow" or module.startswith("petriflow.")) and not self.aliases[receiver.id][1]:
                return None  # a method of another module (atexit.register...)
        kind = {"action": "action", "predicate": "guard", "guard": "guard", "register": "register",
                "register_state": "agent state", "register_resource": "resource"}.get(func.attr)
        if kind == "register" and len(call.args) + len(call.keywords) < 2:
            return None
        return kind

    # Values -------------------------------------------------------------------------
    def value(self, node: ast.expr | None, depth: int = 0) -> Any:
        """The value of a literal expression (module constants, ``f"..."`` of literals,
        ``frozenset({...})`` included), or ``_UNKNOWN``."""
        if node is None or depth > 20:
            return _UNKNOWN
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            return self.value(self.constants.get(node.id), depth + 1)
        if isinstance(node, (ast.Tuple, ast.List, ast.Set)):
            items = [self.value(e, depth + 1) for e in node.elts]
            if any(i is _UNKNOWN for i in items) or any(isinstance(e, ast.Starred) for e in node.elts):
                return _UNKNOWN
            try:
                return {ast.Tuple: tuple, ast.List: list, ast.Set: set}[type(node)](items)
            except TypeError:
                return _UNKNOWN
        if isinstance(node, ast.Dict):
            if any(k is None for k in node.keys):
                return _UNKNOWN
            keys = [self.value(k, depth + 1) for k in node.keys]
            values = [self.value(v, depth + 1) for v in node.values]
            if _UNKNOWN in keys or any(v is _UNKNOWN for v in values):
                return _UNKNOWN
            try:
                return dict(zip(keys, values))
            except TypeError:
                return _UNKNOWN
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            operand = self.value(node.operand, depth + 1)
            if isinstance(operand, (int, float)) and not isinstance(operand, bool):
                return -operand if isinstance(node.op, ast.USub) else operand
            return _UNKNOWN
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
            left, right = self.value(node.left, depth + 1), self.value(node.right, depth + 1)
            if isinstance(left, str) and isinstance(right, str):
                return left + right
            return _UNKNOWN
        if isinstance(node, ast.JoinedStr):
            parts = []
            for part in node.values:
                if isinstance(part, ast.FormattedValue):
                    if part.conversion != -1 or part.format_spec is not None:
                        return _UNKNOWN
                    part = part.value
                item = self.value(part, depth + 1)
                if not isinstance(item, (str, int, float)) or isinstance(item, bool):
                    return _UNKNOWN
                parts.append(str(item))
            return "".join(parts)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords \
                and node.func.id in ("frozenset", "set", "tuple", "list", "dict") and len(node.args) <= 1:
            items = self.value(node.args[0], depth + 1) if node.args else ()
            if items is _UNKNOWN:
                return _UNKNOWN
            try:
                return _BUILTIN_TYPES[node.func.id](items)
            except (TypeError, ValueError):
                return _UNKNOWN
        return _UNKNOWN

    def param_type(self, node: ast.expr) -> Any:
        """A parameter's type: a builtin type name, ``None``, a petriflow class, or a tuple."""
        if isinstance(node, ast.Name) and node.id in _BUILTIN_TYPES and node.id not in self.aliases \
                and node.id not in self.constants:
            return _BUILTIN_TYPES[node.id]
        if isinstance(node, ast.Constant) and node.value is None:
            return type(None)
        if isinstance(node, ast.Call) and _callee(node) == "type" and len(node.args) == 1 \
                and isinstance(node.args[0], ast.Constant) and node.args[0].value is None:
            return type(None)
        if isinstance(node, ast.Tuple):
            kinds = tuple(self.param_type(e) for e in node.elts)
            return _UNKNOWN if _UNKNOWN in kinds else kinds
        if isinstance(node, ast.Name) and isinstance(self.constants.get(node.id), ast.Tuple):
            return self.param_type(self.constants[node.id])
        found = self.petriflow_object(node)
        return found if isinstance(found, type) else _UNKNOWN

    def param(self, name: str, node: ast.expr, gaps: list[str]) -> Param:
        """One declared parameter from its ``Param(...)``/``Port(...)`` call."""
        if isinstance(node, ast.Name) and node.id in self.constants:
            node = self.constants[node.id]
        maker = self.petriflow_object(node.func) if isinstance(node, ast.Call) else _UNKNOWN
        if maker not in (Param, Port) or any(isinstance(a, ast.Starred) for a in node.args) \
                or any(k.arg is None for k in node.keywords):
            gaps.append(f"parameter {name!r} is not a literal Param(...) ({self.at(node)}): its values are not"
                        " checked")
            return Param(object, None)
        given = dict(zip(("doc",) if maker is Port else _PARAM_FIELDS, node.args))
        given.update({k.arg: k.value for k in node.keywords})
        if maker is Port:
            required = self.value(given.get("required")) if "required" in given else False
            if not isinstance(required, bool):
                gaps.append(f"port {name!r}: whether it is required is not a literal ({self.at(node)})")
                required = False
            return Port(required=required)
        fields: dict[str, Any] = {}
        if "type" in given:
            kind = self.param_type(given["type"])
            if kind is _UNKNOWN:
                gaps.append(f"parameter {name!r}: its type {ast.unparse(given['type'])!r} ({self.at(node)}) is"
                            " not a builtin or petriflow type name, so its values' type is not checked")
                kind = object
            fields["type"] = kind
        if "default" in given:
            if self.petriflow_object(given["default"]) is REQUIRED:
                fields["default"] = REQUIRED
            else:
                fields["default"] = self.value(given["default"])
                if fields["default"] is _UNKNOWN:
                    fields["default"] = None
                    gaps.append(f"parameter {name!r}: its default is not a literal ({self.at(node)})")
        for key in ("choices", "low", "high", "places"):
            if key in given:
                value = self.value(given[key])
                if value is _UNKNOWN:
                    gaps.append(f"parameter {name!r}: its {key} is not a literal ({self.at(node)})")
                else:
                    fields[key] = tuple(value) if key == "choices" and isinstance(value, (list, set)) else value
        try:
            return Param(**fields)
        except TypeError:
            gaps.append(f"parameter {name!r} is not a literal Param(...) ({self.at(node)})")
            return Param(object, None)

    def params(self, node: ast.expr | None, gaps: list[str], depth: int = 0) -> dict[str, Param] | None:
        """A ``{name: Param(...)}`` literal (or ``dict(name=Param(...))``), or ``None``."""
        if node is None or (isinstance(node, ast.Constant) and node.value is None):
            return {}
        if isinstance(node, ast.Name) and node.id in self.constants and depth < 20:
            return self.params(self.constants[node.id], gaps, depth + 1)
        if isinstance(node, ast.Dict):
            found: dict[str, Param] = {}
            for key, value in zip(node.keys, node.values):
                if key is None:  # {**Base.params, ...}: a class of the module's, or of petriflow's
                    inherited = self.inherited(value, gaps, depth)
                    if inherited is None:
                        break
                    found.update(inherited)
                    continue
                name = self.value(key)
                if not isinstance(name, str):
                    break
                found[name] = self.param(name, value, gaps)
            else:
                return found
        if isinstance(node, ast.Call) and _callee(node) == "dict" and not node.args \
                and all(k.arg is not None for k in node.keywords):
            return {k.arg: self.param(k.arg, k.value, gaps) for k in node.keywords}
        gaps.append(f"its parameters ({self.at(node)}) are not a literal dict: they are not checked")
        return None

    def inherited(self, node: ast.expr, gaps: list[str], depth: int) -> dict[str, Param] | None:
        """The parameters ``Class.params`` names (a class of the module, or petriflow's)."""
        if not (isinstance(node, ast.Attribute) and node.attr == "params") or depth > 20:
            return None
        owner = node.value
        if isinstance(owner, ast.Name) and len(self.classes.get(owner.id, [])) == 1:
            if id(self.classes[owner.id][0]) in self.resolving:
                return None  # a class's params made of its own
            declared = ActionDeclaration("", self.at(node))
            self.cls(declared, self.classes[owner.id][0], set())
            gaps.extend(declared.gaps)
            return declared.params
        real = self.petriflow_object(owner)
        return dict(real.params) if isinstance(real, type) and issubclass(real, Action) else None

    # Registrations ------------------------------------------------------------------
    def registration(self, call: ast.Call, target: ast.AST | None) -> None:
        """One registering call: ``call`` names it, ``target`` is what it registers."""
        kind = self.kind(call)
        written = call.args[0] if call.args else _keyword(call, "name")
        name = self.value(written)
        if kind == "guard":
            if not isinstance(name, str):
                return self.hidden("guard", call, written)
            gaps: list[str] = []
            reads: Any = None
            if _keyword(call, "reads") is not None:
                reads = self.value(_keyword(call, "reads"))
                if reads is _UNKNOWN:
                    gaps.append(f"the state keys it reads ({self.at(call)}) are not a literal")
                    reads = None
                elif reads is not None:
                    reads = tuple(reads)
            self.found.put("guard", name, GuardDeclaration(name, self.at(call), reads, gaps))
            return None
        if not isinstance(name, str):
            return self.hidden("action", call, written)
        declared = ActionDeclaration(name, self.at(call))
        if kind == "register":
            self.target(declared, target)
        elif isinstance(target, ast.ClassDef):
            self.cls(declared, target, set())
        elif isinstance(target, ast.Name) and len(self.classes.get(target.id, [])) == 1:
            self.cls(declared, self.classes[target.id][0], set())
        else:  # a function; or a decorator made, then applied elsewhere: params from it, the target unseen
            params = call.args[1] if len(call.args) > 1 else _keyword(call, "params")
            declared.params = self.params(params, declared.gaps)
            if not isinstance(target, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Name, ast.Lambda, ast.Attribute)):
                declared.gaps.append(f"what {self.at(call)} is applied to is not seen")
        self.found.put("action", name, declared)
        return None

    def target(self, declared: ActionDeclaration, target: ast.AST | None) -> None:
        """``registry.register(name, target)``: a class of the module, a petriflow class,
        or a lazy ``"module:Class"`` (not read)."""
        if isinstance(target, ast.Name) and len(self.classes.get(target.id, [])) == 1:
            return self.cls(declared, self.classes[target.id][0], set())
        real = self.petriflow_object(target) if isinstance(target, ast.expr) else _UNKNOWN
        if isinstance(real, type) and issubclass(real, Action):
            declared.base, declared.params = real, None
            declared.requires, declared.resources = real.requires, dict(getattr(real, "resources", {}))
            declared.params = dict(real.params)
            return None
        what = ast.unparse(target) if isinstance(target, ast.AST) else "?"
        declared.params = None
        declared.gaps.append(f"the class it registers, {what}, is not one the module defines:"
                             " its parameters are not checked")
        return None

    def cls(self, declared: ActionDeclaration, node: ast.ClassDef, seen: set[int]) -> None:
        """An :class:`Action` subclass of the module: its class attributes, over its bases'."""
        seen = seen | {id(node)}
        self.resolving.add(id(node))
        try:
            self.cls_attributes(declared, node, seen)
        finally:
            self.resolving.discard(id(node))

    def cls_attributes(self, declared: ActionDeclaration, node: ast.ClassDef, seen: set[int]) -> None:
        for base in reversed(node.bases):  # the first base's attributes win, as in the MRO
            if isinstance(base, ast.Name) and len(self.classes.get(base.id, [])) == 1 \
                    and id(self.classes[base.id][0]) not in seen:
                self.cls(declared, self.classes[base.id][0], seen)
                continue
            real = self.petriflow_object(base)
            if isinstance(real, type) and issubclass(real, Action):
                if issubclass(real, declared.base):
                    declared.base = real
                declared.params = dict(real.params)
                declared.requires = real.requires
                declared.resources = dict(getattr(real, "resources", {}))
                if real.agent_state is not None:
                    declared.gaps.append(f"the agent state it reads ({type_names(real.agent_state)}) is not"
                                         " checked against its subnet's")
            elif not (isinstance(real, type) or (isinstance(base, ast.Name) and base.id == "object")):
                declared.params = None  # a petriflow mixin or object declare nothing; anything else may
                declared.gaps.append(f"its base class {ast.unparse(base)} ({self.at(node)}) is not read:"
                                     " what it declares is not checked")
        own: dict[str, ast.expr] = {}
        for item in node.body:
            if isinstance(item, ast.Assign):
                for target in item.targets:
                    if isinstance(target, ast.Name):
                        own[target.id] = item.value
            elif isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name) and item.value is not None:
                own[item.target.id] = item.value
            elif isinstance(item, (ast.FunctionDef, ast.AsyncFunctionDef)) \
                    and item.name in ("check_params", "requirements"):
                declared.gaps.append(f"its own {item.name}() ({self.at(item)}) is not run: what it checks is"
                                     " not checked")
        if "params" in own:
            declared.params = self.params(own["params"], declared.gaps)
        if "requires" in own:
            requires = self.value(own["requires"])
            if isinstance(requires, (set, frozenset, tuple, list)) and all(isinstance(r, str) for r in requires):
                declared.requires = frozenset(requires)
            else:
                declared.gaps.append(f"what it requires ({self.at(own['requires'])}) is not a literal")
        if "resources" in own:
            resources = self.value(own["resources"])
            if isinstance(resources, dict) and all(isinstance(v, str) for v in resources.values()):
                declared.resources = resources
            else:
                declared.resources = {}
                declared.gaps.append(f"the resources it uses ({self.at(own['resources'])}) are not a literal")
        if "agent_state" in own and not (isinstance(own["agent_state"], ast.Constant)
                                         and own["agent_state"].value is None):
            declared.gaps.append(f"the agent state it reads ({ast.unparse(own['agent_state'])}) is not checked"
                                 " against its subnet's")


def _node_value(node: ast.stmt) -> ast.expr | None:
    """The value an assignment statement binds (``None``: not an assignment, or none)."""
    return node.value if isinstance(node, (ast.Assign, ast.AnnAssign)) else None


def _keyword(call: ast.Call, name: str) -> ast.expr | None:
    """The value of the call's keyword argument ``name`` (``None``: not given)."""
    return next((keyword.value for keyword in call.keywords if keyword.arg == name), None)


def _callee(call: ast.Call) -> str | None:
    func = call.func
    return func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else None


def _is_main_guard(node: ast.stmt) -> bool:
    """``if __name__ == "__main__":``: not run when the module is imported."""
    test = getattr(node, "test", None)
    return (isinstance(node, ast.If) and isinstance(test, ast.Compare) and isinstance(test.left, ast.Name)
            and test.left.id == "__name__" and len(test.comparators) == 1
            and isinstance(test.comparators[0], ast.Constant) and test.comparators[0].value == "__main__")



def _module_file(base: Path) -> Path | None:
    """``base.py`` or ``base/__init__.py``, whichever exists."""
    for file in (base.with_name(base.name + ".py"), base / "__init__.py"):
        if file.is_file():
            return file.resolve()
    return None
