"""Reading a run's files: the first step of a run, before anything is checked or bound.

A run is loaded in one direction, each step taking the previous one's typed value::

    read_run (this module)        files -> RunFiles: the net, its run configuration,
                                  its world description, each read and parsed once
    check_run (validation)        RunFiles -> CheckedRun: bound, configuration and
                                  world checked against the net, settings read
    open_run (assembly)           CheckedRun -> Scheduler: the world built, the parts
                                  of the run made
    Scheduler.run                 -> RunResult

Reading finds the run configuration (the one given, else the one the net names with
``run:``, else ``run.yaml`` beside the net, else the defaults) and the world file (the
one given, else the configuration's ``world:``), and checks the world description's
fields (:func:`petriflow.worldfile.check_world`: no pybullet). Nothing is bound here
and no action module is imported. A journal keeps the texts read
(:func:`journal_inputs`), and a resumed run reads them back (:func:`from_journal`)
into the same :class:`RunFiles`.

Examples:
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "run.yaml").write_text("{seed: 7, world: world.yaml}")
    >>> _ = (folder / "world.yaml").write_text("{dt: 0.05, plane: false}")
    >>> _ = (folder / "cell.yaml").write_text("{petriflow: 1, places: [{id: idle, tokens: 1}]}")
    >>> files = read_run(folder / "cell.yaml")
    >>> files.net.id, files.config.seed, files.world.description["dt"]
    ('cell', 7, 0.05)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from petriflow.errors import NetFormatError
from petriflow.io.files import read_text_file
from petriflow.io.safe_yaml import LineDict, LineList
from petriflow.net import Net
from petriflow.runtime.config import RunConfig, load_config

__all__ = ["RunFiles", "WorldFile", "read_run", "read_world", "parse_world", "net_from_text", "net_config",
           "journal_inputs", "from_journal"]


@dataclass(frozen=True)
class WorldFile:
    """A world description, read and checked (not built: no pybullet yet).

    Attributes:
        path: the file it was read from (named in errors).
        text: its text, as read (what a journal keeps).
        description: :func:`~petriflow.worldfile.check_world`'s output; its ``meta``
            keeps the lines of the file, for the settings' errors.
        base: the folder its relative files (URDFs) resolve against.
    """

    path: str
    text: str
    description: dict[str, Any]
    base: Path


@dataclass(frozen=True)
class RunFiles:
    """What a run reads from files, read once (see the module).

    Attributes:
        net: the net, as its file says (the configuration's ``bind:`` not applied yet).
        path: the net's file.
        text: the net file's text (what a journal keeps).
        config: the run configuration found for it.
        world_path: the world file the run uses, if any.
        world: that world, read and checked (``None``: none, or not read).
    """

    net: Net
    path: Path
    text: str
    config: RunConfig
    world_path: Path | None = None
    world: WorldFile | None = None


def net_from_text(text: str, path: str) -> Net:
    """The net in ``text`` (PNML when it starts with ``<``, else YAML), read from ``path``.

    Raises:
        NetFormatError: a malformed net, naming ``path`` and the line.
    """
    text = text.removeprefix("\ufeff")
    if text.lstrip().startswith("<"):
        from petriflow.io.pnml import loads_pnml

        return loads_pnml(text, path=path)
    from petriflow.io.yaml import loads_net

    return loads_net(text, path=path, name=Path(path).stem)


def net_config(net: Net, path: Path) -> RunConfig | None:
    """The run configuration ``net`` (read from ``path``) names, or ``None``.

    Raises:
        NetFormatError: the file it names is missing or malformed.
    """
    named = net.run
    if named is None:
        return None
    if isinstance(named, str):
        file = path.parent / named
        if not file.is_file():
            raise NetFormatError(f"run configuration {named!r} not found (looked for {file}); give it with"
                                 " --config, or put it beside the net", path=str(path), line=net.lines.get("run"))
        return load_config(file)
    return RunConfig.from_dict(_located(named, net.lines), str(path), base=str(path.parent),
                               line=net.lines.get("run"))


def _located(run: dict, lines: dict[str, int]) -> LineDict:
    """A net's inline ``run:`` with the lines of its keys and of their lists' items
    (``run.KEY``, ``run.KEY/I`` in the net's lines), so its errors name them."""
    located = LineDict(run)
    located.line = lines.get("run", 0)
    located.key_lines = {key: lines[f"run.{key}"] for key in run if f"run.{key}" in lines}
    for key, value in run.items():
        if isinstance(value, list) and f"run.{key}/0" in lines:
            items = located[key] = LineList(value)
            items.line = located.key_lines.get(key, located.line)
            items.item_lines = [lines.get(f"run.{key}/{i}", items.line) for i in range(len(value))]
    return located


def _config_for(net: Net, path: Path, given: str | Path | RunConfig | None) -> RunConfig:
    """The run configuration: ``given``, else the net's, else ``run.yaml`` beside it, else the defaults."""
    if isinstance(given, RunConfig):
        return given
    if given is not None:
        return load_config(given)
    found = net_config(net, path)
    if found is None and (path.parent / "run.yaml").is_file():
        found = load_config(path.parent / "run.yaml")
    return found or RunConfig()


def _yaml_error(exc: yaml.YAMLError, path: str) -> NetFormatError:
    """A YAML parser's error as one line naming the file and the line."""
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    problem = getattr(exc, "problem", None)
    if not problem:
        reason = getattr(exc, "reason", None)  # a character YAML does not allow
        problem = (f"{reason} (character {getattr(exc, 'character', '?')!r} at position"
                   f" {getattr(exc, 'position', '?')})" if reason is not None else " ".join(str(exc).split()))
    return NetFormatError(f"malformed YAML: {problem}", path=path, line=mark.line + 1 if mark else None)


def parse_world(text: str, path: str, base: str | Path | None = None) -> WorldFile:
    """The world description in ``text`` (read from ``path``), parsed and checked.

    Args:
        text: the world file's text.
        path: its file, named in errors.
        base: the folder its relative files resolve against (default: ``path``'s).

    Raises:
        NetFormatError: malformed YAML or a bad field, naming the file and the line.
    """
    from petriflow.io.yaml import parse_yaml
    from petriflow.worldfile import check_world

    try:
        data = parse_yaml(text)
    except NetFormatError as exc:
        raise exc.at(path) from None
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, path) from None
    folder = Path(base) if base is not None else Path(path).resolve().parent
    return WorldFile(path, text, check_world(data, path), folder)


def read_world(path: str | Path) -> WorldFile:
    """The world file ``path``, read, parsed and checked (see :func:`parse_world`)."""
    return parse_world(read_text_file(path), str(path))


def read_run(net_path: str | Path, *, config: str | Path | RunConfig | None = None,
             world: str | Path | None = None, with_world: bool = True) -> RunFiles:
    """Read the net in ``net_path``, find and read its run configuration and world.

    Args:
        net_path: the net file.
        config: the run configuration (a file, or one made in code) instead of the
            one the net names.
        world: the world file instead of the one the configuration names.
        with_world: read the world file too (``False``: only find it, for commands
            that do not run the net).

    Raises:
        NetFormatError: a file is missing or malformed (``file:line``).
    """
    net_path = Path(net_path)
    if not net_path.is_file():
        raise NetFormatError("no such file", path=str(net_path))
    text = read_text_file(net_path)
    net = net_from_text(text, str(net_path))
    run_config = _config_for(net, net_path, config)
    world_path = Path(world) if world is not None else (Path(run_config.world) if run_config.world else None)
    world_file = read_world(world_path) if with_world and world_path is not None else None
    return RunFiles(net, net_path, text, run_config, world_path, world_file)


def journal_inputs(files: RunFiles, *, seed: int | None, until: float | None) -> dict[str, Any]:
    """What a journal keeps of a run's files (:class:`~petriflow.runtime.journal.Journal`):
    the texts read, the configuration as data, the seed and time limit (the run's own,
    or the configuration's)."""
    config, world = files.config, files.world
    return {
        "net_file": str(files.path),
        "net_text": files.text,
        "config": {k: v for k, v in config.to_dict().items() if k != "world"},
        "seed": config.seed if seed is None else seed,
        "until": config.until if until is None else until,
        "world_file": None if world is None else world.path,
        "world_base": None if world is None else str(world.base),
        "world_text": None if world is None else world.text,
    }


def from_journal(inputs: dict[str, Any], where: str) -> RunFiles:
    """The files of the run whose journal inputs are ``inputs`` (see :func:`journal_inputs`),
    read from the texts kept there.

    Raises:
        NetFormatError: a text the journal keeps is malformed.
        JournalError: its run configuration is damaged (naming ``where``, the journal).
    """
    from petriflow.runtime.journal import JournalError

    net = net_from_text(inputs["net_text"], inputs["net_file"])
    try:
        config = RunConfig.from_dict(inputs["config"])
    except NetFormatError as exc:
        raise JournalError(f"{where}: a damaged journal: its run configuration: {exc}") from None
    world = None
    if inputs.get("world_text") is not None:
        world = parse_world(inputs["world_text"], inputs["world_file"], inputs.get("world_base"))
    return RunFiles(net, Path(inputs["net_file"]), inputs["net_text"], config,
                    None if world is None else Path(world.path), world)
