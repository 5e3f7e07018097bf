"""The run configuration: seed, limits, channel models, injected faults, world file.

Written as YAML (a file the net names with ``run: FILE``, ``run.yaml`` beside a net,
or the net's own ``run:`` mapping) or built in code::

    seed: 1
    until: 120          # simulated seconds
    dt: 0.01            # tick when no world sets one
    world: world.yaml   # relative to this file
    actions: [my_actions]   # modules that register actions: beside this file or importable
    channels:
      radio: {model: range, threshold_dbm: -63.4375}
    faults:
      - {kill: robot3, at: 110}                       # agent stops; its actions are cancelled
      - {join: monitor, at: 50}                       # agent starts late
      - {drop_link: [robot1, robot2], at: 10, until: 20}
    metrics:            # what `petriflow run` prints at the end (a sweep file's syntax)
      - core.messages
      - done_at: {metric: core.time_of, transition: done}
    bind:               # actions for a net's transitions without editing its file
      register: core.wait                                    # by id, or by label
      "check ticket": {action: core.wait, params: {seconds: 60}}
    bridge:             # subnets whose agents run elsewhere (docs/bridge.md)
      {transport: zenoh, connect: tcp/127.0.0.1:7447, agents: {red: red}}

Examples:
    >>> config = RunConfig.from_dict({"seed": 3, "faults": [{"kill": "r1", "at": 5}]})
    >>> config.seed, config.faults[0]
    (3, Fault(kind='kill', at=5.0, agent='r1', link=(), until=None))
"""

from __future__ import annotations

import importlib
import math
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from petriflow.bridge.spec import BridgeSpec
from petriflow.errors import NetFormatError, did_you_mean
from petriflow.net import Net
from petriflow.outcome import Name
from petriflow.runtime.channel_models import ChannelModel, build_channel
from petriflow.runtime.control import BREAKPOINT_SYNTAX, ControlError, parse_breakpoint
from petriflow.runtime.metrics import MetricRef, parse_refs

__all__ = ["RunConfig", "Fault", "FaultKind", "load_config", "plain_data"]

_KEYS = {"seed", "until", "dt", "world", "channels", "faults", "actions", "stall", "metrics", "bind", "bridge", "breakpoints"}

#: Default of :attr:`RunConfig.stall`: simulated seconds a run may step tick by tick
#: with actions running and no firing starting or ending before it is stopped.
DEFAULT_STALL = 3600.0
#: Folders (besides a configuration's own) its ``world`` and ``actions`` files may be
#: in: the ``PETRIFLOW_PATH`` environment variable, folders separated like ``PATH``.
PATH_VARIABLE = "PETRIFLOW_PATH"


def _finite(value: Any, low: float = 0.0, low_open: bool = False) -> bool:
    """A number of seconds from ``low`` to :data:`petriflow.limits.MAX_SECONDS`."""
    from petriflow import limits

    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        value = float(value)
    except OverflowError:  # an integer of hundreds of digits
        return False
    return math.isfinite(value) and value <= limits.MAX_SECONDS and (value > low if low_open else value >= low)


def allowed_folders(folder: Path | None) -> list[Path]:
    """The folders a configuration in ``folder`` may name files in."""
    folders = [folder.resolve()] if folder is not None else []
    extra = os.environ.get(PATH_VARIABLE, "")
    folders += [Path(p).resolve() for p in extra.split(os.pathsep) if p]
    return folders


def inside(path: Path, folders: list[Path]) -> bool:
    """Whether ``path`` (resolved, links followed) is in one of ``folders``."""
    target = path.resolve()
    return any(target == f or f in target.parents for f in folders)


class FaultKind(Name):
    """The faults a run configuration can inject."""

    KILL = "kill"
    """The agent stops: its running actions are cancelled, its transitions never fire again."""
    JOIN = "join"
    """The agent only starts at the fault's time (a late joiner)."""
    DROP_LINK = "drop_link"
    """Messages between the two agents are lost from ``at`` until ``until``."""
    RESTORE_LINK = "restore_link"
    """In traces only: a dropped link works again (at its ``until``)."""
    LOST = "lost"
    """In traces only: a remote agent stopped answering (its running actions failed)."""
    BACK = "back"
    """In traces only: a lost remote agent announced itself again (a late joiner)."""


_FAULT_KINDS = (FaultKind.KILL.value, FaultKind.JOIN.value, FaultKind.DROP_LINK.value)


@dataclass(frozen=True)
class Fault:
    """A fault injected at simulated time ``at``.

    Attributes:
        kind: a :class:`FaultKind` value: ``kill`` (the agent stops and its running
            actions are cancelled), ``join`` (the agent only starts at ``at``), or
            ``drop_link`` (messages between the two agents of ``link`` are lost from
            ``at`` to ``until``).
    """

    kind: str
    at: float
    agent: str | None = None
    link: tuple[str, ...] = ()
    until: float | None = None


@dataclass
class RunConfig:
    """Everything about a run that is not the net.

    Attributes:
        seed: the run seed.
        until: simulated-time limit in seconds (``None``: none).
        dt: seconds per tick when the world sets none.
        world: the world file (resolved against the configuration's folder).
        channels: ``{channel: model spec}``.
        faults: the faults to inject.
        path: the configuration's file, named in errors.
        actions: modules that register the actions the net uses, imported before
            binding (:meth:`import_actions`): absolute ``.py`` paths (modules found
            beside the configuration) or importable module names.
        stall: simulated seconds a run may step with actions running and no firing
            starting or ending before it stops (``stalled``); ``None``: never.
        metrics: the registered metrics ``petriflow run`` reports at the end (the
            scenario's own measures: bytes sent, map accuracy...), as a sweep file
            names them (:func:`petriflow.runtime.metrics.parse_refs`).
        bind: ``{transition: (action, params)}``: actions bound to a net's transitions
            by the configuration rather than by the net's file (a net drawn in another
            tool), each transition named by its id or by its label (every transition of
            that label); applied by :meth:`bound`, over what the file binds.

    The files a configuration names (``world``, ``.py`` action modules) must be in its
    own folder (or below it), or in a folder listed in ``PETRIFLOW_PATH``: a
    configuration cannot make a run read (and journal) any file of the machine.
    """

    seed: int = 0
    until: float | None = None
    dt: float = 0.01
    world: str | None = None
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)
    faults: list[Fault] = field(default_factory=list)
    path: str | None = None
    actions: list[str] = field(default_factory=list)
    stall: float | None = DEFAULT_STALL
    lines: dict[str, int | None] = field(default_factory=dict, compare=False, repr=False)
    metrics: list[MetricRef] = field(default_factory=list)
    bind: dict[str, tuple[str, dict[str, Any]]] = field(default_factory=dict)
    #: ``{transition: name in bind}`` of the transitions :meth:`bound` bound last.
    bound_by: dict[str, str] = field(default_factory=dict, compare=False, repr=False)
    bridge: BridgeSpec | None = None
    #: breakpoints of a steered run (:mod:`petriflow.runtime.control`'s language):
    #: ``transition NAME``, ``place NAME >= N``, ``lost``, ``failed``.
    breakpoints: list[str] = field(default_factory=list)

    @classmethod
    def from_dict(cls, data: Any, path: str | None = None, *, base: str | None = None,
                  line: int | None = None) -> "RunConfig":
        """Build from parsed YAML; errors name ``path``, the line and the bad key.

        Args:
            data: the parsed configuration (from :func:`~petriflow.io.yaml.parse_yaml`,
                its mappings know their lines).
            path: its file (named in errors).
            base: the folder relative paths resolve against (default: ``path``'s).
            line: the line named when ``data`` does not know one (a net's inline ``run:``).
        """

        def fail(message: str, element: str | None = None, item: Any = None, key: str | None = None):
            at = getattr(item, "line", None)
            if at is None and key is not None:
                at = getattr(data, "key_lines", {}).get(key)
            raise NetFormatError(message, path=path, element=element, line=at or line)

        folder = Path(base) if base is not None else (Path(path).parent if path is not None else None)

        if data is None:
            data = {}
        if not isinstance(data, dict):
            fail("a run configuration is a mapping")
        for key in data:
            if key not in _KEYS:
                fail(f"unknown key {key!r}{did_you_mean(str(key), _KEYS)}", key=key)
        seed, until, dt, stall = _times(data, fail)
        channels = data.get("channels") or {}
        if not isinstance(channels, dict) or not all(isinstance(v, dict) for v in channels.values()):
            fail("channels must map a channel name to its model, e.g. {radio: {model: range}}", key="channels")
        entries = data.get("faults") or []
        if not isinstance(entries, list):
            fail(f"faults must be a list, got {entries!r}", key="faults")
        faults = [cls._fault(entry, lambda message, entry=entry: fail(message, item=entry, key="faults"))
                  for entry in entries]
        lines = {f"faults/{i}": getattr(entry, "line", None) for i, entry in enumerate(entries)}
        lines.update({f"channels/{name}": getattr(channels, "key_lines", {}).get(name) for name in channels})
        binds = data.get("bind") or {}

        def bind_fail(message: str, key: str | None = None) -> None:
            at = getattr(binds, "key_lines", {}).get(key) if key is not None else None
            raise NetFormatError(message, path=path, line=at or getattr(data, "key_lines", {}).get("bind") or line)

        bindings = _bindings(data.get("bind"), bind_fail)
        lines.update({f"bind/{name}": getattr(binds, "key_lines", {}).get(name) for name in bindings})
        lines["actions"] = getattr(data, "key_lines", {}).get("actions")
        lines["bridge"] = getattr(data, "key_lines", {}).get("bridge")
        lines["metrics"] = getattr(data, "key_lines", {}).get("metrics")
        lines = {key: at or getattr(data, "key_lines", {}).get(key.split("/")[0]) or line
                 for key, at in lines.items()}
        world, located = _files(data, folder, fail)
        metrics = [] if data.get("metrics") is None else parse_refs(data["metrics"], fail)
        given = data.get("breakpoints")
        at = getattr(data, "key_lines", {}).get("breakpoints") or line
        lines["breakpoints"] = at
        lines.update({f"breakpoints/{i}": item_at for i, item_at in enumerate(getattr(given, "item_lines", ()))})

        def breakpoint_fail(message: str, i: int | None = None) -> None:
            raise NetFormatError(message, path=path, line=lines.get(f"breakpoints/{i}") or at)

        breakpoints = _breakpoints(given, breakpoint_fail)
        bridge = None if data.get("bridge") is None else BridgeSpec.from_dict(plain_data(data["bridge"]), fail)
        config = cls(seed, None if until is None else float(until), float(dt), world,
                     {str(k): dict(v) for k, v in channels.items()}, faults, path, located,
                     None if stall is None else float(stall), lines, metrics, bindings, bridge=bridge,
                     breakpoints=breakpoints)
        try:
            config.channel_models()  # fail early on a bad model
        except NetFormatError as exc:
            name = (exc.element or "").partition(".")[2]
            raise NetFormatError(exc.message, path=path, line=lines.get(f"channels/{name}"),
                                 element=exc.element) from None
        return config

    def bound(self, net: Net) -> Net:
        """``net`` with the actions of :attr:`bind` bound to its transitions (a copy; the
        net itself when there is nothing to bind).

        Raises:
            NetFormatError: a name is neither a transition's id nor a label of the net,
                naming the configuration's file and line.
        """
        if not self.bind:
            return net
        import dataclasses

        by_label: dict[str, list[str]] = {}
        for transition in net.transitions.values():
            if transition.label:
                by_label.setdefault(transition.label, []).append(transition.id)
        bound = net.copy()
        for name, (action, params) in self.bind.items():
            targets = [name] if name in net.transitions else by_label.get(name, [])
            if not targets:
                raise NetFormatError(
                    f"bind: {name!r} is neither a transition nor a transition's label of net {net.id!r}"
                    f"{did_you_mean(name, [*net.transitions, *by_label])}",
                    path=self.path, line=self.lines.get(f"bind/{name}"))
            for tid in targets:
                bound.transitions[tid] = dataclasses.replace(bound.transitions[tid], action=action,
                                                             params=dict(params))
                self.bound_by[tid] = name
        return bound

    def blame(self, error: NetFormatError) -> NetFormatError:
        """``error`` about a transition this configuration bound (an unknown action, a bad
        parameter), located at its ``bind:`` entry rather than at the net's file."""
        name = self.bound_by.get(error.element or "")
        if name is None:
            return error
        return NetFormatError(f"bind: {name!r}: {error.message}", path=self.path,
                              line=self.lines.get(f"bind/{name}"), element=error.element)

    def import_actions(self) -> None:
        """Import the modules of :attr:`actions` (each registers its actions when
        imported; one already imported is not imported again).

        Raises:
            NetFormatError: a module cannot be found or fails to import, naming the
                configuration and the import error.
        """
        for entry in self.actions:
            try:
                _import_module(entry)
            except Exception as exc:
                raise NetFormatError(f"cannot import action module {entry!r}: {type(exc).__name__}: {exc}",
                                     path=self.path, element="actions") from None

    def unimported_actions(self) -> list[str]:
        """The modules of :attr:`actions` not imported in this process (their actions are
        not registered: a command that does not import user code cannot check them)."""
        return [entry for entry in self.actions if not _imported(entry)]

    @staticmethod
    def _fault(entry: Any, fail) -> Fault:
        if not isinstance(entry, dict):
            fail(f"a fault is a mapping such as {{kill: robot1, at: 10}}, got {entry!r}")
        kinds = [k for k in _FAULT_KINDS if k in entry]
        extra = set(entry) - set(_FAULT_KINDS) - {"at", "until"}
        if len(kinds) != 1 or extra:
            fail(f"a fault needs exactly one of {', '.join(_FAULT_KINDS)} plus 'at' (and 'until'"
                 f" for drop_link); got keys {sorted(str(k) for k in entry)}")
        kind = kinds[0]
        at = entry.get("at")
        if not _finite(at):
            fail(f"fault {kind}: 'at' must be a time in seconds from 0 to 1e12, got {at!r}")
        until = entry.get("until")
        if kind == "drop_link":
            link = entry[kind]
            if not (isinstance(link, list) and len(link) == 2 and all(isinstance(a, str) for a in link)):
                fail(f"drop_link takes two agent names, got {link!r}")
            if until is not None and (not _finite(until) or until < at):
                fail(f"drop_link: 'until' must be a time >= 'at' and at most 1e12, got {until!r}")
            return Fault(kind, float(at), None, tuple(link), None if until is None else float(until))
        if until is not None:
            fail(f"fault {kind}: 'until' only applies to drop_link")
        if not isinstance(entry[kind], str):
            fail(f"fault {kind}: name one agent, got {entry[kind]!r}")
        return Fault(kind, float(at), entry[kind])

    def channel_models(self, registry: Any = None) -> dict[str, ChannelModel]:
        """Fresh channel models for a run (models keep per-run state such as a bus);
        model names not built in are looked up in ``registry`` (default: the run registry)."""
        return {name: build_channel(name, spec, registry=registry) for name, spec in self.channels.items()}

    def check(self, net: Net) -> None:
        """Check that faults name agents, channels name channels and the bridge names
        subnets of ``net``.

        Raises:
            NetFormatError: naming the configuration file and the unknown name.
        """
        agents = {(s.agent or s.id) for s in net.subnets.values()}
        for i, fault in enumerate(self.faults):
            for agent in (fault.agent, *fault.link):
                if agent is not None and agent not in agents:
                    raise NetFormatError(
                        f"fault {fault.kind} names unknown agent {agent!r}{did_you_mean(agent, agents)}",
                        path=self.path, line=self.lines.get(f"faults/{i}"),
                    )
        for i, spec in enumerate(self.breakpoints):
            point = parse_breakpoint(spec)
            names = net.transitions if point.kind == "transition" else net.places if point.kind == "place" else None
            if names is not None and point.name not in names:
                raise NetFormatError(f"breakpoint {spec!r}: net {net.id!r} has no {point.kind} {point.name!r}"
                                     f"{did_you_mean(point.name, list(names))}", path=self.path,
                                     line=self.lines.get(f"breakpoints/{i}") or self.lines.get("breakpoints"))
        if self.bridge is not None:
            names = {*net.subnets, *agents}
            for subnet in self.bridge.agents:
                if subnet not in names:
                    raise NetFormatError(f"bridge: agents: {subnet!r} is no subnet of net {net.id!r}"
                                         f"{did_you_mean(subnet, names)}", path=self.path, line=self.lines.get("bridge"))
        used = {p.channel for p in net.places.values() if p.channel}
        for name in self.channels:
            if name not in used:
                raise NetFormatError(
                    f"channel {name!r} is not used by any place of net {net.id!r}"
                    f"{did_you_mean(name, used)}",
                    path=self.path, line=self.lines.get(f"channels/{name}"),
                )

    def to_dict(self) -> dict[str, Any]:
        """Plain data (what the journal keeps)."""
        faults = []
        for f in self.faults:
            entry: dict[str, Any] = {f.kind: list(f.link) if f.kind == "drop_link" else f.agent, "at": f.at}
            if f.until is not None:
                entry["until"] = f.until
            faults.append(entry)
        data = {"seed": self.seed, "until": self.until, "dt": self.dt, "world": self.world,
                "channels": self.channels, "faults": faults, "actions": list(self.actions), "stall": self.stall}
        if self.metrics:
            data["metrics"] = [{m.name: {"metric": m.metric, **m.params}} for m in self.metrics]
        if self.bridge is not None:
            data["bridge"] = self.bridge.to_dict()
        if self.bind:
            data["bind"] = {name: {"action": action, "params": dict(params)}
                            for name, (action, params) in self.bind.items()}
        if self.breakpoints:
            data["breakpoints"] = list(self.breakpoints)
        return data


def _breakpoints(given: Any, fail: Callable[..., Any]) -> list[str]:
    """A configuration's ``breakpoints``: a list of breakpoints, each checked for its
    syntax (the names are checked against the net by :meth:`RunConfig.check`); ``fail``
    is told the message and the index of the bad one."""
    if given is None:
        return []
    if not isinstance(given, list):
        fail(f"breakpoints is a list ({BREAKPOINT_SYNTAX}), got {given!r}")
    out = []
    for i, entry in enumerate(given):
        try:
            out.append(parse_breakpoint(entry).text)
        except ControlError as exc:
            fail(str(exc), i)
    return out


def _bindings(given: Any, fail: Callable[..., Any]) -> dict[str, tuple[str, dict[str, Any]]]:
    """A configuration's ``bind``: ``{transition or label: action}`` or
    ``{transition or label: {action: NAME, params: {...}}}``, checked for its shape (the
    names are checked against the net by :meth:`RunConfig.bound`, the actions and their
    parameters when the net is bound)."""
    if given is None:
        return {}
    if not isinstance(given, dict):
        fail("bind maps a transition (its id or label) to an action, e.g. {register: core.wait}")
    out = {}
    for name, entry in given.items():
        if isinstance(entry, str):
            entry = {"action": entry}
        if not isinstance(entry, dict) or set(entry) - {"action", "params"} or not isinstance(
                entry.get("action"), str) or not entry["action"].strip():
            fail(f"bind: {name!r} takes an action name, or {{action: NAME, params: {{...}}}}, got {entry!r}",
                 key=str(name))
        params = entry.get("params") or {}
        if not isinstance(params, dict) or not all(isinstance(k, str) for k in params):
            fail(f"bind: {name!r}: params must map parameter names to values, got {params!r}", key=str(name))
        out[str(name)] = (entry["action"], {k: plain_data(v) for k, v in params.items()})
    return out


def plain_data(value: Any) -> Any:
    """Parsed YAML (mappings and lists that know their lines) as plain data.

    Examples:
        >>> from petriflow.io.yaml import parse_yaml
        >>> type(plain_data(parse_yaml("{a: [1]}"))["a"])
        <class 'list'>
    """
    if isinstance(value, dict):
        return {k: plain_data(v) for k, v in value.items()}
    if isinstance(value, list):
        return [plain_data(v) for v in value]
    return value


def _times(data: Any, fail: Callable[..., Any]) -> tuple[int, Any, Any, Any]:
    """A configuration's ``seed``, ``until``, ``dt`` and ``stall``, checked."""
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int):
        fail(f"seed must be a whole number, got {seed!r}", key="seed")
    until = data.get("until")
    if until is not None and not _finite(until):
        fail(f"until must be a number of seconds from 0 to 1e12, got {until!r}", key="until")
    dt = data.get("dt", 0.01)
    if not _finite(dt, 1e-6) or dt > 3600:
        fail(f"dt must be a number of seconds from 0.000001 to 3600, got {dt!r}", key="dt")
    stall = data.get("stall", DEFAULT_STALL)
    if stall is not None and not _finite(stall, 0.0, low_open=True):
        fail(f"stall must be a number of seconds > 0 and at most 1e12, or null (never), got {stall!r}", key="stall")
    return seed, until, dt, stall


def _files(data: Any, folder: Path | None, fail: Callable[..., Any]) -> tuple[str | None, list[str]]:
    """A configuration's ``world`` file and ``actions`` modules, resolved against its
    folder and checked to lie in the folders it may name."""
    world = data.get("world")
    if world is not None and not isinstance(world, str):
        fail(f"world must be a file name, got {world!r}", key="world")
    allowed = allowed_folders(folder)
    if world is not None and folder is not None:
        if not inside(folder / world, allowed):
            fail(f"world {world!r} is outside the configuration's folder (list its folder in"
                 f" {PATH_VARIABLE} to allow it)", "world", key="world")
        world = str(folder / world)
    actions = data.get("actions") or []
    if isinstance(actions, str):
        actions = [actions]
    if not isinstance(actions, list) or not all(isinstance(a, str) and a.strip() for a in actions):
        fail(f"actions must list modules (names or .py files), got {actions!r}", key="actions")
    located = [_locate_module(a, folder) for a in actions]
    for given, where in zip(actions, located):
        if Path(where).is_absolute() and folder is not None and not inside(Path(where), allowed):
            fail(f"action module {given!r} is outside the configuration's folder (list its folder in"
                 f" {PATH_VARIABLE} to allow it)", "actions", key="actions")
    return world, located


def _locate_module(entry: str, folder: Path | None) -> str:
    """An action module entry as stored: an absolute path when it is a ``.py`` file or
    a module (file or package) found in ``folder``, else the module name as given."""
    entry = entry.strip()
    if entry.endswith(".py"):
        file = Path(entry) if folder is None or Path(entry).is_absolute() else folder / entry
        return str(file.resolve())
    if folder is not None and entry.isidentifier():
        if (folder / f"{entry}.py").is_file():
            return str((folder / f"{entry}.py").resolve())
        if (folder / entry / "__init__.py").is_file():
            return str((folder / entry).resolve())
    return entry


def _imported(entry: str) -> bool:
    """Whether the action module ``entry`` (as :func:`_locate_module` stores it) is imported."""
    path = Path(entry)
    if entry.endswith(".py") or path.is_absolute():
        name = path.stem if entry.endswith(".py") else path.name
        loaded = sys.modules.get(name)
        if loaded is None:
            return False
        where = Path(getattr(loaded, "__file__", "") or "").resolve()
        return where in (path.resolve(), (path / "__init__.py").resolve())
    return entry in sys.modules


def _import_module(entry: str) -> None:
    """Import an action module: a file or package folder path, or a module name."""
    path = Path(entry)
    if entry.endswith(".py") or path.is_absolute():
        folder, name = (path.parent, path.stem) if entry.endswith(".py") else (path.parent, path.name)
        if not (path.is_file() or (path / "__init__.py").is_file()):
            raise FileNotFoundError(f"no such file: {entry}")
        loaded = sys.modules.get(name)
        if loaded is not None:
            where = Path(getattr(loaded, "__file__", "") or "").resolve()
            if where not in (path.resolve(), (path / "__init__.py").resolve()):
                raise ImportError(f"another module named {name!r} is already imported (from {where})")
            return
        sys.path.insert(0, str(folder))
        try:
            importlib.import_module(name)
        finally:
            try:
                sys.path.remove(str(folder))
            except ValueError:
                pass
        return
    importlib.import_module(entry)


def load_config(path: str | Path) -> RunConfig:
    """Read a run configuration YAML file (safe loader)."""
    from petriflow.io.files import read_yaml_file

    return RunConfig.from_dict(read_yaml_file(path, lines=True), str(path))
