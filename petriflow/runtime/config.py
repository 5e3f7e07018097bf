"""The run configuration: seed, limits, channel models, injected faults, world file.

Written as YAML (``run.yaml`` beside a net) or built in code::

    seed: 1
    until: 120          # simulated seconds
    dt: 0.01            # tick when no world sets one
    world: world.yaml   # relative to this file
    channels:
      radio: {model: range, threshold_dbm: -63.4375}
    faults:
      - {kill: robot3, at: 110}                       # agent stops; its actions are cancelled
      - {join: monitor, at: 50}                       # agent starts late
      - {drop_link: [robot1, robot2], at: 10, until: 20}

Examples:
    >>> config = RunConfig.from_dict({"seed": 3, "faults": [{"kill": "r1", "at": 5}]})
    >>> config.seed, config.faults[0]
    (3, Fault(kind='kill', at=5.0, agent='r1', link=(), until=None))
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError, did_you_mean
from petriflow.net import Net
from petriflow.runtime.channels import ChannelModel, build_channel

__all__ = ["RunConfig", "Fault", "load_config"]

_KEYS = {"seed", "until", "dt", "world", "channels", "faults"}
_FAULT_KINDS = ("kill", "join", "drop_link")


@dataclass(frozen=True)
class Fault:
    """A fault injected at simulated time ``at``.

    Attributes:
        kind: ``kill`` (the agent stops and its running actions are cancelled),
            ``join`` (the agent only starts at ``at``), or ``drop_link`` (messages
            between the two agents of ``link`` are lost from ``at`` to ``until``).
    """

    kind: str
    at: float
    agent: str | None = None
    link: tuple[str, ...] = ()
    until: float | None = None


@dataclass
class RunConfig:
    """Everything about a run that is not the net."""

    seed: int = 0
    until: float | None = None
    dt: float = 0.01
    world: str | None = None
    channels: dict[str, dict[str, Any]] = field(default_factory=dict)
    faults: list[Fault] = field(default_factory=list)
    path: str | None = None

    @classmethod
    def from_dict(cls, data: Any, path: str | None = None) -> "RunConfig":
        """Build from parsed YAML; errors name ``path`` and the bad key."""

        def fail(message: str, element: str | None = None):
            raise NetFormatError(message, path=path, element=element)

        if data is None:
            data = {}
        if not isinstance(data, dict):
            fail("a run configuration is a mapping")
        for key in data:
            if key not in _KEYS:
                fail(f"unknown key {key!r}{did_you_mean(str(key), _KEYS)}")
        seed = data.get("seed", 0)
        if isinstance(seed, bool) or not isinstance(seed, int):
            fail(f"seed must be a whole number, got {seed!r}")
        until = data.get("until")
        if until is not None and (isinstance(until, bool) or not isinstance(until, (int, float)) or until < 0):
            fail(f"until must be a number of seconds >= 0, got {until!r}")
        dt = data.get("dt", 0.01)
        if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not dt > 0:
            fail(f"dt must be a number of seconds > 0, got {dt!r}")
        channels = data.get("channels") or {}
        if not isinstance(channels, dict) or not all(isinstance(v, dict) for v in channels.values()):
            fail("channels must map a channel name to its model, e.g. {radio: {model: range}}")
        faults = [cls._fault(entry, fail) for entry in data.get("faults") or []]
        world = data.get("world")
        if world is not None and path is not None:
            world = str(Path(path).parent / world)
        config = cls(seed, None if until is None else float(until), float(dt), world,
                     {str(k): dict(v) for k, v in channels.items()}, faults, path)
        config.channel_models()  # fail early on a bad model
        return config

    @staticmethod
    def _fault(entry: Any, fail) -> Fault:
        if not isinstance(entry, dict):
            fail(f"a fault is a mapping such as {{kill: robot1, at: 10}}, got {entry!r}")
        kinds = [k for k in _FAULT_KINDS if k in entry]
        extra = set(entry) - set(_FAULT_KINDS) - {"at", "until"}
        if len(kinds) != 1 or extra:
            fail(f"a fault needs exactly one of {', '.join(_FAULT_KINDS)} plus 'at' (and 'until'"
                 f" for drop_link); got keys {sorted(entry)}")
        kind = kinds[0]
        at = entry.get("at")
        if isinstance(at, bool) or not isinstance(at, (int, float)) or at < 0:
            fail(f"fault {kind}: 'at' must be a time in seconds >= 0, got {at!r}")
        until = entry.get("until")
        if kind == "drop_link":
            link = entry[kind]
            if not (isinstance(link, list) and len(link) == 2 and all(isinstance(a, str) for a in link)):
                fail(f"drop_link takes two agent names, got {link!r}")
            if until is not None and (not isinstance(until, (int, float)) or until < at):
                fail(f"drop_link: 'until' must be a time >= 'at', got {until!r}")
            return Fault(kind, float(at), None, tuple(link), None if until is None else float(until))
        if until is not None:
            fail(f"fault {kind}: 'until' only applies to drop_link")
        if not isinstance(entry[kind], str):
            fail(f"fault {kind}: name one agent, got {entry[kind]!r}")
        return Fault(kind, float(at), entry[kind])

    def channel_models(self) -> dict[str, ChannelModel]:
        """Fresh channel models for a run (models keep per-run state such as a bus)."""
        return {name: build_channel(name, spec) for name, spec in self.channels.items()}

    def check(self, net: Net) -> None:
        """Check that faults name agents and channels name channels of ``net``.

        Raises:
            NetFormatError: naming the configuration file and the unknown name.
        """
        agents = {(s.agent or s.id) for s in net.subnets.values()}
        for fault in self.faults:
            for agent in (fault.agent, *fault.link):
                if agent is not None and agent not in agents:
                    raise NetFormatError(
                        f"fault {fault.kind} names unknown agent {agent!r}{did_you_mean(agent, agents)}",
                        path=self.path,
                    )
        used = {p.channel for p in net.places.values() if p.channel}
        for name in self.channels:
            if name not in used:
                raise NetFormatError(
                    f"channel {name!r} is not used by any place of net {net.id!r}"
                    f"{did_you_mean(name, used)}",
                    path=self.path,
                )

    def to_dict(self) -> dict[str, Any]:
        """Plain data (what the journal keeps)."""
        faults = []
        for f in self.faults:
            entry: dict[str, Any] = {f.kind: list(f.link) if f.kind == "drop_link" else f.agent, "at": f.at}
            if f.until is not None:
                entry["until"] = f.until
            faults.append(entry)
        return {"seed": self.seed, "until": self.until, "dt": self.dt, "world": self.world,
                "channels": self.channels, "faults": faults}


def load_config(path: str | Path) -> RunConfig:
    """Read a run configuration YAML file (safe loader)."""
    from petriflow.io.files import read_yaml_file

    return RunConfig.from_dict(read_yaml_file(path), str(path))
