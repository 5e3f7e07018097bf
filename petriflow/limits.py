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

Beside the capacities, the fixed rules every reader shares: :func:`parse_integer` (the
one rule for every whole number read from a file or an option: ASCII digits, at most
:data:`MAX_INTEGER` = 2**60), :func:`parse_decimal` (a decimal number in ASCII) and
:func:`check_seconds` (simulated times).

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

import math
import os
import re

from petriflow.errors import NumberError, PetriflowError, did_you_mean

__all__ = ["LIMITS", "ENVIRONMENT_VARIABLE", "MAX_SECONDS", "MAX_INTEGER", "parse", "from_environment",
           "check_seconds", "parse_integer", "parse_decimal", "integer_argument"]

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

#: The largest magnitude of a whole number petriflow reads, from any file or option:
#: 2**60 = 1,152,921,504,606,846,976 (:func:`parse_integer`). A fixed rule, not a
#: capacity: the analysis counts tokens in 64-bit integers, and counts and weights up to
#: 2**60 keep every sum it makes exact.
MAX_INTEGER = 2**60

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
        try:  # float() reads any script's digits: ASCII ones only, as everywhere
            number = float(value.replace("_", "")) if sep and value.isascii() else float("nan")
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


_INTEGER = re.compile(r"[+-]?[0-9]+")  # a range of code points: ASCII digits only, unlike \d
_MAX_DIGITS = len(str(MAX_INTEGER))
_XML_SPACE = " \t\r\n"


def parse_integer(value: str | int, what: str = "the value", *, minimum: int | None = None) -> int:
    """The whole number ``value`` is, by petriflow's one rule for them: every whole number
    read from a file or an option goes through here (PNML counts, weights, priorities,
    positions and tool data, YAML integers, ``--marking`` counts, ``--steps`` and the
    other integer options).

    The rule: an optional sign (``+`` or ``-``) and the ASCII digits ``0``-``9``,
    decimal, nothing else (XSD's ``integer``: no other script's digits, no underscores,
    no ``0x``); whitespace around it (space, tab, newline) is ignored; a magnitude of at
    most :data:`MAX_INTEGER` (2**60). An ``int`` (a number JSON or YAML has already read)
    is checked against the same bounds.

    Args:
        value: the text as written, or an ``int``.
        what: what the number is, for the message (``"initial marking"``).
        minimum: the smallest value allowed (``0`` for counts, ``1`` for weights).

    Raises:
        NumberError: one line naming ``what`` and the value (its start, when long);
            callers add the file and line.

    Examples:
        >>> parse_integer(" 42\\n", "arc weight"), parse_integer("-7", "priority")
        (42, -7)
        >>> parse_integer("\\u0663", "initial marking")
        Traceback (most recent call last):
        ...
        petriflow.errors.NumberError: initial marking must be written with the ASCII digits 0-9, got '\u0663' ('\u0663' is U+0663 ARABIC-INDIC DIGIT THREE)
        >>> parse_integer("9" * 5000, "priority")
        Traceback (most recent call last):
        ...
        petriflow.errors.NumberError: priority '999999999999...' (5000 digits) is beyond 2**60 = 1,152,921,504,606,846,976, the largest whole number petriflow reads
        >>> parse_integer(-1, "tokens", minimum=0)
        Traceback (most recent call last):
        ...
        petriflow.errors.NumberError: tokens must be a whole number >= 0, got -1
    """
    if isinstance(value, str):
        text = value.strip(_XML_SPACE)
        if not _INTEGER.fullmatch(text):
            raise NumberError(_malformed(text, what))
        digits = text.lstrip("+-").lstrip("0")
        if len(digits) > _MAX_DIGITS:  # never int() thousands of digits (Python refuses 4,300)
            shown = text if len(text) <= 30 else f"{_shown(text)} ({len(digits)} digits)"
            raise NumberError(f"{what} {shown} is {_beyond(text.startswith('-'))}")
        number = int(text)
    elif isinstance(value, int) and not isinstance(value, bool):
        number = value
    else:
        raise NumberError(f"{what} must be a whole number, got {_shown(value)}")
    if not -MAX_INTEGER <= number <= MAX_INTEGER:
        shown = str(number) if number.bit_length() <= 100 else "of more than 30 digits"
        raise NumberError(f"{what} {shown} is {_beyond(number < 0)}")
    if minimum is not None and number < minimum:
        raise NumberError(f"{what} must be a whole number >= {minimum}, got {number}")
    return number


#: A decimal number in ASCII (XSD's ``decimal`` or ``double``, without INF and NaN):
#: ``float()`` alone would read any script's digits, and underscores.
_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def parse_decimal(text: str | None) -> float | None:
    """``text`` as a finite float when it is an ASCII decimal number, else ``None``.

    Examples:
        >>> parse_decimal(" 120.5 "), parse_decimal("1e3"), parse_decimal("\u0663"), parse_decimal("nan")
        (120.5, 1000.0, None, None)
    """
    text = (text or "").strip(_XML_SPACE)
    if not _DECIMAL.fullmatch(text):
        return None
    value = float(text)
    return value if math.isfinite(value) else None


def _beyond(negative: bool) -> str:
    if negative:
        return f"below -2**60 = -{MAX_INTEGER:,}, the smallest whole number petriflow reads"
    return f"beyond 2**60 = {MAX_INTEGER:,}, the largest whole number petriflow reads"


def _shown(value: object) -> str:
    """``value``'s repr, cut to its start when long."""
    text = repr(value) if not isinstance(value, str) or len(value) <= 24 else repr(value[:12] + "...")
    return text if len(text) <= 40 else text[:36] + "..."


def _malformed(text: str, what: str) -> str:
    import unicodedata

    odd = next((c for c in text if not c.isascii() and unicodedata.decimal(c, None) is not None), None)
    if odd is None:
        odd = next((c for c in text if not c.isascii() and c.isdigit()), None)  # superscripts and the like
    if odd is not None:
        name = unicodedata.name(odd, "a digit")
        return (f"{what} must be written with the ASCII digits 0-9, got {_shown(text)}"
                f" ({odd!r} is U+{ord(odd):04X} {name})")
    return f"{what} must be a whole number (ASCII digits 0-9, an optional sign), got {_shown(text)}"


def integer_argument(text: str) -> int:
    """The ``type`` of every whole-number command-line option (``--steps``, ``--seed``,
    ``--max-states``, ``--workers``...): :func:`parse_integer`'s rule, its refusal an
    argparse error (one line, exit 2). Each command checks its own option's range.

    Examples:
        >>> integer_argument("12")
        12
    """
    import argparse

    try:
        return parse_integer(text)
    except NumberError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def number_argument(text: str) -> float:
    """The ``type`` of every decimal command-line option (``--until``, ``--poses``,
    ``--progress-every``, ``--max-mb``): a number written in ASCII (``2.5``, ``1e3``,
    ``inf`` where the option allows it), never another script's digits; each command
    checks its own option's range.

    Examples:
        >>> number_argument("2.5")
        2.5
    """
    import argparse

    stripped = text.strip()
    if not stripped.isascii() or "_" in stripped:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number written in ASCII (digits 0-9, '.', 'e')")
    try:
        return float(stripped)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None


def from_environment() -> None:
    """Apply :data:`ENVIRONMENT_VARIABLE` (if set) to this module's limits."""
    text = os.environ.get(ENVIRONMENT_VARIABLE)
    if text:
        globals().update(parse(text))
