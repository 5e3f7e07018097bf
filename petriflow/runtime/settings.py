"""World-file settings a scenario reads: declared sections, checked when the world loads.

A world file describes a scene (bodies, robots, cameras) and, under its ``meta`` key,
what a scenario needs besides: the office plan the bidding robots navigate, the maze
of a swarm, which robot wears which marker. Each such entry is a *section*, and the
actions (or resources) that read one declare it as a :class:`Section`: its name under
``meta``, and each :class:`Setting` it holds (type, default, range, one line of
documentation; a mapping's declared ``fields``, a list's ``items``). The binding
gathers the sections the bound actions declare, and the world file is checked
against them when it is loaded, before the run starts: an unknown name (with a close
match), a missing one, a value of the wrong type or out of range fails with the world
file's name and line. The action reads the checked values, defaults filled in, with
``ctx.settings``; nothing reads ``meta`` as a free-form dictionary.

The checks are :class:`~petriflow.runtime.action.Param`'s (a setting is a parameter
of the world file), so the same words describe both.

Examples:
    >>> MAZE = Section("maze", {
    ...     "cell": Setting(float, 0.5, "side of a cell (m)", low=0.01),
    ...     "rows": Setting(int, doc="cells along y", low=1),
    ...     "origin": Setting(list, [0.0, 0.0], "world x, y of the lower-left corner",
    ...                       items=Setting(float)),
    ... })
    >>> MAZE.read({"rows": 4})
    {'cell': 0.5, 'rows': 4, 'origin': [0.0, 0.0]}
    >>> MAZE.read({"rows": 4, "cel": 1.0}, path="world.yaml")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: world.yaml: 'meta.maze': unknown setting 'cel' (did you mean 'cell'?) (it takes: cell, rows, origin)
    >>> MAZE.read({"rows": 0}, path="world.yaml")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: world.yaml: 'meta.maze': setting 'rows' must be >= 1, got 0
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

from petriflow.capabilities import Described, provides
from petriflow.errors import NetFormatError, did_you_mean
from petriflow.runtime.action import REQUIRED, Param
from petriflow.runtime.config import plain_data

__all__ = ["Setting", "Section", "read_settings", "sections_of", "world_section"]


@dataclass(frozen=True)
class Setting(Param):
    """One declared setting of a world file's section: a :class:`Param` (type, default,
    doc, choices, low, high), and for a mapping the ``fields`` it holds, for a list
    the ``items`` (each checked as that setting).

    Attributes:
        fields: ``{name: Setting}`` of a mapping value (``None``: any keys).
        items: the setting each item of a list value is (``None``: any items).
    """

    fields: Mapping[str, "Setting"] | None = None
    items: "Setting | None" = None

    def read(self, name: str, value: Any, where: str, path: str | None, line: int | None) -> Any:
        """``value`` checked (defaults of declared fields filled in), errors at ``path:line``."""
        try:
            value = self.check(name, value, where, what="setting")
        except NetFormatError as exc:
            raise NetFormatError(exc.message, path=path, line=line, element=where) from None
        if self.fields is not None and isinstance(value, Mapping):
            return _read_fields(self.fields, value, f"{where}.{name}", path)
        if self.items is not None and isinstance(value, list):
            at = getattr(value, "line", None) or line
            return [self.items.read(f"{name}[{i}]", item, where, path, getattr(item, "line", None) or at)
                    for i, item in enumerate(value)]
        return plain_data(value)


def _read_fields(fields: Mapping[str, Setting], given: Mapping[str, Any], where: str,
                 path: str | None) -> dict[str, Any]:
    """The mapping ``given`` checked against ``fields`` (see :meth:`Section.read`)."""
    lines = getattr(given, "key_lines", {})
    line = getattr(given, "line", None)
    for name in given:
        if name not in fields:
            raise NetFormatError(f"unknown setting {name!r}{did_you_mean(str(name), fields)}"
                                 f" (it takes: {', '.join(fields) or 'none'})", path=path,
                                 line=lines.get(name, line), element=where)
    out: dict[str, Any] = {}
    for name, setting in fields.items():
        if name in given:
            out[name] = setting.read(name, given[name], where, path, lines.get(name, line))
        elif setting.default is REQUIRED:
            raise NetFormatError(f"missing setting {name!r}", path=path, line=line, element=where)
        else:
            out[name] = copy.deepcopy(setting.default)
    return out


@dataclass(frozen=True)
class Section:
    """A section of a world file's settings (``meta: {NAME: {...}}``) that actions read.

    Attributes:
        name: the key under the world file's ``meta``.
        fields: ``{setting name: Setting}``; a name not declared is an error.
        doc: one line for ``petriflow actions`` and the docs.
        required: whether a world must have the section (else every setting takes its
            default, and a required setting then fails).
    """

    name: str
    fields: Mapping[str, Setting] = field(default_factory=dict)
    doc: str = ""
    required: bool = False

    def read(self, given: Any, *, path: str | None = None, line: int | None = None) -> dict[str, Any]:
        """The section's values from ``given`` (its mapping in the world file, or
        ``None`` when the file has none), checked, defaults filled in.

        Raises:
            NetFormatError: ``path:line: 'meta.NAME': ...`` for an unknown or missing
                setting, a value of the wrong type or out of range.
        """
        where = f"meta.{self.name}"
        if given is None:
            if self.required:
                raise NetFormatError(f"the world has no {where} (the actions of this net read it)", path=path,
                                     line=line)
            given = {}
        if not isinstance(given, Mapping):
            raise NetFormatError(f"{where} is a mapping of settings, got {given!r}", path=path,
                                 line=getattr(given, "line", None) or line)
        return _read_fields(self.fields, given, where, path)


def sections_of(declared: Iterable[tuple[str, Section]]) -> dict[str, Section]:
    """``{name: Section}`` of ``(who, section)`` declarations; two declarations of one
    name must be the same section.

    Raises:
        NetFormatError: two different sections of one name (naming who declares them).
    """
    found: dict[str, tuple[str, Section]] = {}
    for who, section in declared:
        seen = found.setdefault(section.name, (who, section))
        if seen[1] != section:
            raise NetFormatError(f"{who} and {seen[0]} declare different settings sections"
                                 f" {section.name!r}: one section, one declaration", element=who)
    return {name: section for name, (_, section) in found.items()}


def read_settings(meta: Any, sections: Mapping[str, Section], *, path: str | None = None,
                  line: int | None = None) -> dict[str, dict[str, Any]]:
    """``{section: {name: value}}`` of the world's ``meta`` for the declared ``sections``
    (other keys of ``meta`` are left alone: data no action reads).

    Raises:
        NetFormatError: as :meth:`Section.read`, at ``path`` and the line.
    """
    meta = meta or {}
    lines = getattr(meta, "key_lines", {})
    return {name: section.read(meta.get(name), path=path, line=lines.get(name, getattr(meta, "line", None) or line))
            for name, section in sections.items()}


def world_section(world: Any, section: Section) -> dict[str, Any]:
    """The declared ``section`` of ``world``'s settings, checked, defaults filled in: for
    code that holds a world but no action context (a channel model bound to the world, a
    metric, a drawing); an action reads ``ctx.settings``. A world without a world file
    (not :class:`~petriflow.capabilities.Described`) gives the defaults.

    Raises:
        NetFormatError: the world file's settings do not check (``file:line``).
    """
    if not provides(world, Described):
        return section.read(None)
    return read_settings(world.meta, {section.name: section}, path=world.path)[section.name]
