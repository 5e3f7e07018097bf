"""Checking a run's inputs, once: the second step of a run (files read -> checked run).

:func:`check_run` takes the :class:`~petriflow.runtime.loading.RunFiles` that reading
made and checks everything a run needs before anything is built or written: the
configuration's ``bind:`` applied to the net, the configuration's action modules
imported, the net bound to the registry (every action, parameter, port and guard,
``file:line``), the configuration checked against the net (its faults and channels
name what the net has), the counts a run can hold, the world an action needs (a world
at all, the capabilities it uses) and the world file's settings the actions read.
What it returns, a :class:`CheckedRun`, is what assembly takes
(:func:`~petriflow.runtime.assembly.open_run`).

:func:`validate` is the same check for a net and configuration already in hand (a net
built in code, a scheduler made directly): it returns the binding marked checked, so
nothing checks it again.

Examples:
    >>> from petriflow.io.yaml import loads_net
    >>> from petriflow.runtime.config import RunConfig
    >>> typo = "{petriflow: 1, places: [{id: i, tokens: 1}], transitions: [{id: t, action: core.wiat, in: [i]}]}"
    >>> validate(loads_net(typo, path="n.yaml"), RunConfig())
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: n.yaml:1: 't': unknown action 'core.wiat' (did you mean 'core.wait' or 'core.set' or 'core.fail'?)
    >>> validate(loads_net(typo.replace("wiat", "wait")), RunConfig(), world=None).checked
    True
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from petriflow.errors import NetFormatError
from petriflow.net import Net
from petriflow.runtime.binding import Binding, bind, check_sizes, check_world
from petriflow.runtime.config import RunConfig
from petriflow.runtime.loading import RunFiles, WorldFile
from petriflow.runtime.registry import Registry
from petriflow.runtime.settings import read_settings

__all__ = ["CheckedRun", "check_run", "validate", "settings_of", "UNKNOWN"]

#: ``world=`` of :func:`validate` when the run's world is not known yet (not checked).
UNKNOWN: Any = type("Unknown", (), {"__repr__": lambda self: "UNKNOWN"})()


@dataclass(frozen=True)
class CheckedRun:
    """A run's inputs, checked: what assembly puts together.

    Attributes:
        net: the net, the configuration's ``bind:`` applied.
        binding: the net bound, checked (:attr:`Binding.checked`).
        config: the run configuration.
        world: the world file, read and checked (``None``: none, or a world the
            caller makes).
        settings: ``{section: {name: value}}``, the world file's settings the bound
            actions read (:mod:`petriflow.runtime.settings`).
        path: the net's file (``None`` for a net made in code).
    """

    net: Net
    binding: Binding
    config: RunConfig
    world: WorldFile | None = None
    settings: dict[str, dict[str, Any]] = field(default_factory=dict)
    path: Path | None = None

    @classmethod
    def of(cls, net: Net, binding: Binding, config: RunConfig, world: WorldFile | None = None,
           path: Path | None = None) -> "CheckedRun":
        """The checked run of a net whose ``binding`` is checked (:func:`validate`) for
        ``world``: the world file's settings the actions read, read and checked.

        Raises:
            NetFormatError: a setting is unknown, missing or bad (the world file's line).
        """
        meta = None if world is None else world.description.get("meta")
        settings = read_settings(meta, binding.sections, path=None if world is None else world.path)
        return cls(net, binding, config, world, settings, path)


def validate(net: Net, config: RunConfig, *, binding: Binding | None = None, registry: Registry | None = None,
             path: str | None = None, world: Any = UNKNOWN, has_world: bool | None = None) -> Binding:
    """Check a run's inputs once; returns the binding, marked checked.

    Args:
        net: the net.
        config: its run configuration.
        binding: the net already bound (else it is bound to ``registry`` here).
        registry: where names are looked up when binding here.
        path: the net's file, named in errors.
        world: the world the run will have (an object, its class, ``True`` for a world
            file, ``None`` for none; :data:`UNKNOWN`: not known yet, not checked).
        has_world: ``world`` as a yes or no (``True``: a world file).

    Raises:
        NetFormatError: ``file:line`` for what does not bind, a fault or channel naming
            nothing in the net, counts a run cannot hold, an action needing a world (or
            a capability of it) the run lacks.
    """
    if has_world is not None:
        world = has_world
    if binding is not None and binding.checked and world is UNKNOWN:
        return binding
    if binding is None:
        try:
            if config.bridge is not None:  # the remote subnets' transitions: goals to their agents
                from petriflow.bridge.remote import bind_remote

                config.check(net)  # the subnets it names, at the configuration's line
                from petriflow.runtime.registry import default_registry

                binding = bind_remote(net, config.bridge, registry or default_registry,
                                      lambda local: bind(local, registry, path=path), path)
            else:
                binding = bind(net, registry, path=path)
        except NetFormatError as exc:
            raise config.blame(exc) from None
    config.check(net)
    check_sizes(net, path or net.path)
    if world is not UNKNOWN:
        check_world(binding, world, path or net.path)
    return dataclasses.replace(binding, checked=True)


def settings_of(world: Any, binding: Binding) -> dict[str, dict[str, Any]]:
    """The settings the bound actions read, from a world made in code (its ``meta``,
    when it has one, as a :class:`petriflow.world.World` does; else the defaults).

    Raises:
        NetFormatError: a setting is unknown, missing or bad (naming the world's file).
    """
    from petriflow.capabilities import Described, missing

    if world is not None and not missing(world, Described):
        return read_settings(world.meta, binding.sections, path=world.path)
    return read_settings(None, binding.sections)


def check_run(files: RunFiles, *, registry: Registry | None = None, import_actions: bool = True) -> CheckedRun:
    """Check what :func:`~petriflow.runtime.loading.read_run` read (see the module).

    Args:
        files: the run's files, read.
        registry: where names are looked up (default: the run registry).
        import_actions: import the action modules the configuration names (what
            running does).

    Raises:
        NetFormatError: ``file:line`` for the first thing that does not check.
    """
    config, path = files.config, str(files.path)
    net = config.bound(files.net)  # the configuration's bind: over what the file binds
    if import_actions:
        config.import_actions()
    binding = validate(net, config, registry=registry, path=path, world=files.world is not None)
    return CheckedRun.of(net, binding, config, files.world, files.path)
