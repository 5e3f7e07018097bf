"""What a trial reads, found once: for the resume fingerprint and for shipping to a cluster.

:func:`collect` builds every row of a sweep (as :func:`~petriflow.sweep.load.check_sweep`
does: nothing runs) and gathers the files its
trials read: the net (each row's, when the net's name holds ``${param}``), the run
configuration, the world description and the files it names (URDFs and the meshes they
name), the action modules (a ``.py`` file or a package folder), and a net builder's
module when it is the user's own (not an installed package). The result, a
:class:`Bundle`, gives

* :meth:`Bundle.digest`: the sweep's fingerprint from those files' *contents* (and the
  sweep's net, run, set and metrics, with paths relative to the bundle's folder), so
  an edited net, world or action module makes ``--resume`` refuse, while the same
  project moved to another folder resumes;
* :meth:`Bundle.stage` and :meth:`Bundle.relative`: the files laid out in a folder (a
  Ray ``working_dir``) and payloads whose paths are relative to it, so a trial runs on
  a node that has none of the driver's paths.

:func:`stage_petriflow` lays out petriflow itself (an editable install's mapped
subpackages included) for Ray's ``py_modules``; :func:`requirements` lists
petriflow's own dependencies for Ray's ``pip`` field on nodes that lack them.

Examples:
    >>> import tempfile, pathlib
    >>> from petriflow.sweep.spec import Sweep
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "n.yaml").write_text("petriflow: 1\\nplaces: [{id: i, tokens: 1}, o]\\n"
    ...     "transitions: [{id: t, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}]\\n")
    >>> sweep = Sweep.from_dict({"petriflow-sweep": 1, "net": "n.yaml"}, folder / "s.yaml")
    >>> bundle = collect(sweep)
    >>> sorted(bundle.hashes)
    ['n.yaml']
    >>> bundle.relative(sweep.payload(sweep.trials()[0]))["sweep"]["net"]
    'n.yaml'
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import re
import shutil
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.sweep.spec import Sweep, canonical, placeholders, substitute

__all__ = ["Bundle", "collect", "stage_petriflow", "requirements", "file_digest"]

#: Files never copied with a package folder.
_SKIP = shutil.ignore_patterns("__pycache__", "*.pyc", "*.pyo", ".git", "*.nbi", "*.nbc")
#: File names inside a world description or a URDF that are other files it reads.
_FILE_VALUE = re.compile(r".+\.(urdf|sdf|xml|obj|stl|dae|mtl|png|jpe?g|bmp|tga|yaml|yml)\Z", re.I)
_URDF_FILE = re.compile(r"""filename\s*=\s*["']([^"']+)["']""")
#: The folder of the petriflow package this process runs (this file is petriflow/sweep/ship.py).
_PETRIFLOW = Path(__file__).parent.parent


def file_digest(path: Path) -> str:
    """SHA-256 of a file's bytes."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


@dataclass
class Bundle:
    """The files a sweep's trials read.

    Attributes:
        root: the folder every file lies in (their deepest common folder).
        files: ``{path relative to root (with /): absolute path}``.
        hashes: ``{path relative to root: SHA-256 of its content}`` (every file but the
            sweep file, whose net, run, set and metrics the digest holds as data).
        modules: the user's own Python modules or packages a trial imports by name
            (a net builder's), shipped beside petriflow.
        sweep: the sweep.
    """

    root: Path
    files: dict[str, Path]
    hashes: dict[str, str]
    modules: list[Path]
    sweep: Sweep
    module_hashes: dict[str, str] = field(default_factory=dict)

    def _rel(self, path: str) -> str:
        return Path(os.path.relpath(path, self.root)).as_posix()

    def relative(self, payload: dict[str, Any]) -> dict[str, Any]:
        """``payload`` with the sweep's paths relative to :attr:`root` (a trial run in
        a copy of the folder, :meth:`stage`, finds every file)."""
        spec = dict(payload["sweep"])
        spec["path"] = self._rel(spec["path"])
        if isinstance(spec["net"], str):
            spec["net"] = self._rel(spec["net"])
        if spec["run"] is not None:
            spec["run"] = self._rel(spec["run"])
        return dict(payload, sweep=spec)

    def digest(self) -> str:
        """The sweep's fingerprint: its net, run, set and metrics (paths relative to
        :attr:`root`) and the content of every file its trials read."""
        data = self.relative({"sweep": self.sweep.to_data()})["sweep"]
        del data["timeout"], data["name"], data["path"]
        data["files"] = self.hashes
        data["modules"] = self.module_hashes
        return hashlib.sha256(canonical(data).encode()).hexdigest()[:16]

    def stage(self, folder: Path) -> Path:
        """Copy every file into ``folder`` at its relative path; returns ``folder``."""
        for rel, path in self.files.items():
            target = folder / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(path, target)
        return folder

    def path_variable(self) -> str | None:
        """``PETRIFLOW_PATH`` as a trial in the staged folder needs it: the driver's
        folders that lie under :attr:`root`, made relative."""
        from petriflow.runtime.config import PATH_VARIABLE

        folders = []
        for entry in os.environ.get(PATH_VARIABLE, "").split(os.pathsep):
            if entry and _inside(Path(entry).resolve(), self.root):
                folders.append(self._rel(str(Path(entry).resolve())))
        return os.pathsep.join(folders) or None


def _inside(path: Path, folder: Path) -> bool:
    return path == folder or folder in path.parents


def _package_files(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts
            and p.suffix not in (".pyc", ".pyo")]


def _installed(origin: Path) -> bool:
    """Whether a module file belongs to an installed distribution (or petriflow):
    what a node gets from its own environment, not from the sweep."""
    if any(part in ("site-packages", "dist-packages") for part in origin.parts):
        return True
    if _inside(origin, _PETRIFLOW.resolve()):
        return True
    for name, module in list(sys.modules.items()):
        if name.startswith("__editable__") and isinstance(getattr(module, "MAPPING", None), dict):
            if any(_inside(origin, Path(p).resolve()) for p in module.MAPPING.values()):
                return True
    return False


def _user_module(name: str) -> Path | None:
    """The file or package folder of the top-level module ``name`` when it is the
    user's own (found on the driver's path, not installed), else ``None``."""
    top = name.split(".")[0]
    try:
        spec = importlib.util.find_spec(top)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or spec.origin in ("built-in", "frozen"):
        return None
    origin = Path(spec.origin).resolve()
    if _installed(origin):
        return None
    return origin.parent if origin.name == "__init__.py" else origin


def _world_files(world: str, data: Any, add) -> None:
    """The files a world description names (values that are existing files beside it),
    and the meshes and textures each URDF among them names."""
    base = Path(world).resolve().parent

    def walk(node: Any) -> None:
        if isinstance(node, dict):
            for value in node.values():
                walk(value)
        elif isinstance(node, list):
            for value in node:
                walk(value)
        elif isinstance(node, str) and _FILE_VALUE.match(node):
            candidate = base / node
            if candidate.is_file():
                add(candidate)
                if candidate.suffix.lower() in (".urdf", ".sdf", ".xml"):
                    _urdf_files(candidate, add)

    walk(data)


def _urdf_files(urdf: Path, add) -> None:
    try:
        text = urdf.read_text(errors="replace")
    except OSError:
        return
    for name in _URDF_FILE.findall(text):
        if "://" in name:
            continue
        candidate = urdf.parent / name
        if candidate.is_file():
            add(candidate)


def collect(sweep: Sweep) -> Bundle:
    """Build every row of ``sweep`` (nothing runs) and gather the files its trials read.

    A row that cannot be built adds what it names that exists (its trials will record
    the error, on any backend).
    """
    from petriflow.sweep.trial import TrialError, build

    found: dict[Path, None] = {}
    modules: dict[Path, None] = {}

    def add(path: str | Path) -> None:
        path = Path(path).resolve()
        if path.is_file():
            found[path] = None
        elif (path / "__init__.py").is_file():
            for item in _package_files(path):
                found[item.resolve()] = None

    add(sweep.path)
    spec = sweep.to_data()
    net = sweep.net
    if isinstance(net, dict):
        module = _user_module(net["builder"].partition(":")[0])
        if module is not None:
            modules[module] = None
    seeded = isinstance(net, str) and "seed" in placeholders(net)
    for row in sweep.rows:
        for seed in (sweep.seeds if seeded else sweep.seeds[:1]):
            if isinstance(net, str):
                add(substitute(net, dict(row.params, seed=seed)))
            try:
                built = build(spec, row.params, seed)
            except (TrialError, NetFormatError, PetriflowError, OSError):
                continue
            config = built.config
            if config.path and Path(config.path).is_file():
                add(config.path)
            for entry in config.actions:
                if Path(entry).is_absolute() or entry.endswith(".py"):
                    add(entry)
                else:
                    module = _user_module(entry)
                    if module is not None:
                        modules[module] = None
            if config.world is not None:
                add(config.world)
                _world_files(config.world, built.world, add)
    if sweep.run is not None:
        add(sweep.run)
    paths = list(found)
    root = Path(os.path.commonpath([str(p.parent) for p in paths]))
    files = {Path(os.path.relpath(p, root)).as_posix(): p for p in sorted(paths)}
    # the sweep file's own content is in the digest as its net, run, set and metrics
    hashes = {rel: file_digest(p) for rel, p in files.items() if p != Path(sweep.path).resolve()}
    module_hashes = {}
    for module in modules:
        items = _package_files(module) if module.is_dir() else [module]
        for item in sorted(items):
            module_hashes[f"{module.name}/{item.relative_to(module).as_posix()}" if module.is_dir()
                          else module.name] = file_digest(item)
    return Bundle(root, files, hashes, list(modules), sweep, module_hashes)


def stage_petriflow(folder: Path) -> Path:
    """Copy the petriflow package this process runs into ``folder/petriflow`` (with the
    subpackages an editable install maps from other folders); returns that folder."""
    source = _PETRIFLOW
    target = folder / "petriflow"
    shutil.copytree(source, target, ignore=_SKIP)
    for name, module in list(sys.modules.items()):
        mapping = getattr(module, "MAPPING", None) if name.startswith("__editable__") else None
        if not isinstance(mapping, dict):
            continue
        for package, where in sorted(mapping.items(), key=lambda item: item[0].count(".")):
            parts = package.split(".")
            if parts[0] != "petriflow" or len(parts) == 1:
                continue
            shutil.copytree(where, target.joinpath(*parts[1:]), ignore=_SKIP, dirs_exist_ok=True)
    return target


def requirements() -> list[str]:
    """petriflow's own dependencies (no extras), as its installed metadata lists them."""
    from importlib import metadata

    try:
        listed = metadata.requires("petriflow") or []
    except metadata.PackageNotFoundError:
        return []
    return [r.split(";")[0].strip() for r in listed if "extra" not in r.partition(";")[2]]
