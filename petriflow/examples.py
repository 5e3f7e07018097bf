"""The example and scenario nets shipped with petriflow, found from any folder.

The repository's ``nets/`` folder (one folder per scenario: nets, worlds, run
configurations, README) is installed with the package, so tests and scripts need not
run from the repository's root::

    from petriflow import examples
    from petriflow.io import load_net
    from petriflow.testing import fire_one
    from petriflow.world import load_world

    net = load_net(examples.path("passage", "passage.yaml"))
    fired = fire_one(net, "red_approach", world=load_world(examples.path("passage", "world.yaml")))

Examples:
    >>> "passage" in names() and "smart" in names()
    True
    >>> path("passage", "passage.yaml").name
    'passage.yaml'
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from petriflow.errors import PetriflowError, did_you_mean

__all__ = ["folder", "names", "path"]


def folder() -> Path:
    """The folder holding the shipped scenarios (the repository's ``nets/``)."""
    return Path(str(resources.files("petriflow.nets")))


def names() -> list[str]:
    """The shipped scenarios, by folder name."""
    return sorted(p.name for p in folder().iterdir() if p.is_dir() and not p.name.startswith(("_", ".")))


def path(scenario: str, file: str | None = None) -> Path:
    """The folder of ``scenario`` (e.g. ``"passage"``), or ``file`` in it.

    Raises:
        PetriflowError: no such scenario or file (with close matches).
    """
    where = folder() / scenario
    if not where.is_dir():
        raise PetriflowError(f"no example {scenario!r}{did_you_mean(scenario, names())} (there are: "
                             f"{', '.join(names())})")
    if file is None:
        return where
    target = where / file
    if not target.exists():
        there = sorted(p.name for p in where.iterdir())
        raise PetriflowError(f"example {scenario!r} has no {file!r}{did_you_mean(file, there)}")
    return target
