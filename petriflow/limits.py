"""The sizes petriflow refuses to go beyond, in one place.

Files come from other people and other tools. Each limit below stops one way a file
could exhaust memory or time (an alias bomb, a deep nest, a net whose invariants
need a matrix of billions of entries) with a one-line error instead; the defaults are
far above any real net, world or trace. The checks read these names when they run, so
raising one takes effect at once:

* from Python: ``petriflow.limits.RUN_TOKENS = 50_000_000``;
* from the command line: ``PETRIFLOW_LIMITS="RUN_TOKENS=5e7,YAML_VALUES=1e7" petriflow ...``
  (read by :func:`from_environment` when a command starts).

``docs/limits.md`` lists every limit, the options that go with them, and what each
one costs when raised.

Examples:
    >>> from petriflow import limits
    >>> limits.parse("RUN_TOKENS=2e7, YAML_DEPTH=128")
    {'RUN_TOKENS': 20000000, 'YAML_DEPTH': 128}
    >>> limits.parse("TOKENS=1")
    Traceback (most recent call last):
    ...
    petriflow.errors.PetriflowError: PETRIFLOW_LIMITS: unknown limit 'TOKENS' (did you mean 'RUN_TOKENS'?)
"""

from __future__ import annotations

import os

from petriflow.errors import PetriflowError, did_you_mean

__all__ = ["LIMITS", "ENVIRONMENT_VARIABLE", "MAX_SECONDS", "parse", "from_environment", "check_seconds"]

#: Nesting depth of YAML collections (nets, worlds, run configurations).
YAML_DEPTH = 64
#: Values in one YAML file once its aliases are expanded (an alias bomb's size).
YAML_VALUES = 1_000_000
#: Nesting depth of JSON (PNML tool data, trace lines, journal inputs).
JSON_DEPTH = 64
#: Nesting depth of PNML pages.
PNML_PAGE_DEPTH = 100
#: Entries of the dense matrix the P- and T-invariant search starts from
#: (places x (places + transitions)); beyond it the invariants are skipped with a note.
INVARIANT_CELLS = 16_000_000
#: Entries (places x transitions) up to which the reachability report computes the
#: incidence matrix's basis (elimination is cubic); beyond it the basis is skipped.
BASIS_ENTRIES = 1_000_000
#: Tokens one place starts a run with, and the largest arc weight a run fires: a run
#: keeps every token's data.
RUN_TOKENS = 10_000_000
#: Firings in one instant of simulated time before a run is stopped as Zeno.
FIRINGS_PER_INSTANT = 100_000
#: Bodies (boxes, grid wall runs, robots) in one world.
WORLD_BODIES = 100_000
#: Width and height of a world camera's image, in pixels.
CAMERA_PIXELS = 4096
#: Firings one ``petriflow simulate`` may make (``--steps``): the token game of an
#: unbounded net never deadlocks, and every firing is printed and kept.
SIMULATE_STEPS = 1_000_000

#: The longest simulated time anything may name (a run's ``until``, a fault's time, a
#: stall limit): 10**12 s, about 31,700 years. A fixed rule, not a capacity: beyond it
#: a time divided by a world's step no longer fits a float's exact integers.
MAX_SECONDS = 1e12

#: The names :func:`parse` accepts.
LIMITS = ("YAML_DEPTH", "YAML_VALUES", "JSON_DEPTH", "PNML_PAGE_DEPTH", "INVARIANT_CELLS", "BASIS_ENTRIES",
          "RUN_TOKENS", "FIRINGS_PER_INSTANT", "WORLD_BODIES", "CAMERA_PIXELS", "SIMULATE_STEPS")

#: The environment variable :func:`from_environment` reads.
ENVIRONMENT_VARIABLE = "PETRIFLOW_LIMITS"


def parse(text: str) -> dict[str, int]:
    """``"NAME=value,NAME=value"`` as ``{name: value}`` (values are whole numbers >= 1,
    written ``20000000``, ``20_000_000`` or ``2e7``).

    Raises:
        PetriflowError: an unknown name or a value that is not a whole number >= 1.
    """
    values: dict[str, int] = {}
    for item in filter(None, (part.strip() for part in text.split(","))):
        name, sep, value = (s.strip() for s in item.partition("="))
        if name not in LIMITS:
            raise PetriflowError(f"{ENVIRONMENT_VARIABLE}: unknown limit {name!r}{did_you_mean(name, LIMITS)}")
        try:
            number = float(value.replace("_", "")) if sep else float("nan")
        except ValueError:
            number = float("nan")
        if not (1 <= number < 2**62 and number == int(number)):
            raise PetriflowError(f"{ENVIRONMENT_VARIABLE}: {name} must be a whole number >= 1, got {value!r}")
        values[name] = int(number)
    return values


def check_seconds(value: object, what: str) -> float:
    """``value`` as a simulated time in seconds: a finite number from 0 to
    :data:`MAX_SECONDS`.

    Raises:
        PetriflowError: naming ``what`` and the value.

    Examples:
        >>> check_seconds(2, "--until")
        2.0
        >>> check_seconds(1e308, "--until")
        Traceback (most recent call last):
        ...
        petriflow.errors.PetriflowError: --until must be a time from 0 to 1e+12 s, got 1e+308
    """
    good = not isinstance(value, bool) and isinstance(value, (int, float))
    if good:
        try:
            seconds = float(value)
        except OverflowError:
            good = False
        else:
            good = 0 <= seconds <= MAX_SECONDS
    if not good:
        shown = repr(value) if not isinstance(value, int) or abs(value) < 10**30 else "a number of more than 30 digits"
        raise PetriflowError(f"{what} must be a time from 0 to {MAX_SECONDS:g} s, got {shown}")
    return seconds


def from_environment() -> None:
    """Apply :data:`ENVIRONMENT_VARIABLE` (if set) to this module's limits."""
    text = os.environ.get(ENVIRONMENT_VARIABLE)
    if text:
        globals().update(parse(text))
