"""A run's events in columns: how a run's page holds its trace compactly.

Every event is split into a *template* and its numbers. The template is the event's
record (kind, transition, agent, data) with each number in it replaced by a
placeholder naming a column; templates repeat (a transition's start event differs from
its last one only in its firing number and time), so each distinct one is stored once
and each event keeps only the index of its template. The numbers go into columns, one
per kind of event and place in the record (the firing numbers of start events, the
arrival times of messages, one body's x coordinates in pose events...), each stored as
integers (decimal fractions as integers at the column's own scale, so ``0.4`` is ``4``
at scale 1), as differences from the previous value where that is smaller, in
variable-length bytes; a number the column's scale does not hold exactly (a rare one
with more decimal places, ``0.30000000000000004``, ``1e-07``) goes into a column of
eight-byte floats, and an integer past 2**50 stays in its template. Strings stay in the
templates, except at a place in the records with very many different strings (it gets
a column of indices into its strings). The event's time is such a number too, and its
``seq`` a column when it is not the event's index.

:func:`encode` gives the templates and columns as one block of bytes, which the page
holds compressed; :func:`decode` (and the page's script, for the events it shows)
rebuilds each event's record from them: the same values as the trace's JSON line (a
float with an integer value may come back as an integer, ``1.0 == 1``).

Examples:
    >>> from petriflow.runtime.trace import Event
    >>> events = [Event(0, 0.0, "run", data={"marking": {"i": 1}}),
    ...           Event(1, 0.4, "start", "t", "a", {"firing": 1, "consumed": {"i": 1}}),
    ...           Event(2, 2.5, "end", "t", "a", {"firing": 1, "outcome": "ok", "produced": {"o": 1}})]
    >>> decode(encode(events)) == [json.loads(e.to_json()) for e in events]
    True
"""

from __future__ import annotations

import json
import math
import struct
import zlib
from collections import Counter
from typing import Any

__all__ = ["encode", "encoded", "decode", "decoded", "MARK"]

#: Starts a placeholder string in a template: ``MARK + "c.j"`` is value ``j`` of the
#: event's values in column ``c``. A recorded string that starts with it goes into a
#: column of strings, so a template's string that starts with it is always a placeholder.
MARK = "\u0001"

#: Integers (and scaled decimals) up to this size go into columns: their differences and
#: zig-zag codes stay exact in a JavaScript number (53 bits).
_LIMIT = 2 ** 50
_MAX_SCALE = 9
#: A place in the records with more different strings than this gets a column of them.
_MANY_STRINGS = 512


def _decimals(value: float) -> int | None:
    """How many decimal places ``repr(value)`` has (``None``: exponent form, ``-0.0``)."""
    text = repr(value)
    if "e" in text or "n" in text or (value == 0.0 and math.copysign(1.0, value) < 0):
        return None
    whole, _, fraction = text.partition(".")
    return 0 if fraction == "0" else len(fraction)


def _scaled(value: float, scale: int) -> int | None:
    """``value`` as an integer ``n`` with ``n / 10**scale == value`` exactly, if there is one."""
    places = _decimals(value)
    if places is None or places > scale:
        return None
    text = repr(value)
    whole, _, fraction = text.partition(".")
    digits = int(whole + fraction) if fraction != "0" else int(whole)
    n = digits * 10 ** (scale - (places if fraction != "0" else 0))
    if abs(n) >= _LIMIT or n / 10 ** scale != value:
        return None
    return n


def _where(path: tuple, key: Any) -> tuple:
    """The column place of a value under ``key`` (a map's key or a list's position; list
    positions past 3 share one place, ``+``)."""
    if isinstance(key, int):
        return path + (key if key < 4 else "+",)
    return path + (key,)


def _walk(value: Any, path: tuple, visit) -> None:
    if isinstance(value, dict):
        for key, item in value.items():
            _walk(item, _where(path, key), visit)
    elif isinstance(value, list):
        for k, item in enumerate(value):
            _walk(item, _where(path, k), visit)
    else:
        visit(path, value)


def _varints(values: list[int]) -> bytes:
    out = bytearray()
    append = out.append
    for n in values:
        u = n * 2 if n >= 0 else -n * 2 - 1
        while u >= 0x80:
            append((u & 0x7F) | 0x80)
            u >>= 7
        append(u)
    return bytes(out)


def _read_varints(data: bytes, at: int, count: int) -> tuple[list[int], int]:
    out = []
    for _ in range(count):
        u = shift = 0
        while True:
            b = data[at]
            at += 1
            u |= (b & 0x7F) << shift
            shift += 7
            if b < 0x80:
                break
        out.append(u >> 1 if u % 2 == 0 else -(u + 1) // 2)
    return out, at


def _size(values: list[int]) -> int:
    """About how many bytes ``values`` take compressed (as a column keeps them)."""
    plain = _varints(values)
    gaps = _varints([b - a for a, b in zip([0] + values, values)])
    return min(len(zlib.compress(plain, 6)), len(zlib.compress(gaps, 6)))


class _Column:
    def __init__(self, name: str, kind: str, scale: int = 0) -> None:
        self.name, self.kind, self.scale = name, kind, scale
        self.values: list[Any] = []
        self.contexts: list[Any] = []  # each value's template and position in it
        self.strings: dict[str, int] = {}

    def add(self, value: Any, context: Any = None) -> None:
        self.values.append(value)
        self.contexts.append(context)

    def encoded(self) -> tuple[dict[str, Any], bytes]:
        about: dict[str, Any] = {"name": self.name, "type": self.kind, "count": len(self.values)}
        if self.kind == "f":
            data = struct.pack(f"<{len(self.values)}d", *self.values)
        elif self.kind == "s":
            data = _varints([self.strings.setdefault(v, len(self.strings)) for v in self.values])
            about["strings"] = list(self.strings)
        else:  # 0: the values; 1: less the one before; 2: less the one before at its template's place
            last: dict[Any, int] = {}
            same = []
            for value, context in zip(self.values, self.contexts):
                same.append(value - last.get(context, 0))
                last[context] = value
            ways = [_varints(self.values), _varints([b - a for a, b in zip([0] + self.values, self.values)]),
                    _varints(same)]
            sizes = [len(zlib.compress(way, 6)) for way in ways]
            delta = sizes.index(min(sizes))
            data = ways[delta]
            about.update(delta=delta, scale=self.scale if self.kind == "d" else 0)
        about["bytes"] = len(data)
        return about, data


def encode(events: list[Any]) -> bytes:
    """The events (:class:`petriflow.runtime.trace.Event`) as templates and columns,
    one block of bytes: four bytes giving the length of a JSON header (the templates,
    the columns' descriptions), the header, then each column's bytes in turn."""
    return encoded(events)[0]


def encoded(events: list[Any]) -> tuple[bytes, list[int]]:
    """:func:`encode`'s block and each event's template number."""
    # first pass: the decimal places each place's numbers need, how many strings it has
    places: dict[tuple, Counter] = {}
    strings: dict[tuple, set] = {}

    def look(path: tuple, value: Any) -> None:
        if isinstance(value, float):
            places.setdefault(path, Counter())[_decimals(value)] += 1
        elif isinstance(value, str) and path not in many:
            seen = strings.setdefault(path, set())
            seen.add(value)
            if len(seen) > _MANY_STRINGS:
                many.add(path)
                del strings[path]

    many: set[tuple] = set()
    for event in events:
        look(("time",), event.time)
        _walk(event.data, (event.kind,), look)
    scales = {}
    for path, counts in places.items():  # the fewest places that hold 99.9 % of the numbers
        total, held = sum(counts.values()), 0
        for k in range(_MAX_SCALE + 1):
            held += counts.get(k, 0)
            if held >= 0.999 * total:
                break
        scales[path] = k
    columns: list[_Column] = []
    index: dict[tuple, int] = {}

    def column(path: tuple, kind: str) -> int:
        key = path + (kind,)
        number = index.get(key)
        if number is None:
            number = index[key] = len(columns)
            columns.append(_Column("/".join(map(str, path)) + ":" + kind, kind, scales.get(path, 0)))
        return number

    template_column = column(("template",), "i")
    seq_column = None
    if any(e.seq != i for i, e in enumerate(events)):
        seq_column = column(("seq",), "i")
    templates: dict[str, int] = {}
    shapes: list[Any] = []

    def value(path: tuple, item: Any, used: dict[int, int], found: list) -> Any:
        if isinstance(item, bool) or item is None:
            return item
        if isinstance(item, int):
            if abs(item) >= _LIMIT:
                return item
            c = column(path, "i")
        elif isinstance(item, float):
            n = _scaled(item, scales[path])
            if n is None:
                c = column(path, "f")
            else:
                c, item = column(path, "d"), n
        elif isinstance(item, str):
            if path not in many and not item.startswith(MARK):
                return item
            c = column(path, "s")
        else:
            return item
        j = used[c] = used.get(c, -1) + 1
        found.append((c, j, item))
        return f"{MARK}{c}.{j}"

    def shape(item: Any, path: tuple, used: dict[int, int], found: list) -> Any:
        if isinstance(item, dict):
            return {k: shape(v, _where(path, k), used, found) for k, v in item.items()}
        if isinstance(item, list):
            return [shape(v, _where(path, k), used, found) for k, v in enumerate(item)]
        return value(path, item, used, found)

    for event in events:
        used: dict[int, int] = {}
        found: list[tuple[int, int, Any]] = []
        if seq_column is not None:
            columns[seq_column].add(event.seq)
        skeleton = [event.kind, event.transition, event.agent, shape(event.data, (event.kind,), used, found),
                    value(("time",), event.time, used, found)]
        key = json.dumps(skeleton, separators=(",", ":"), ensure_ascii=False)
        number = templates.get(key)
        if number is None:
            number = templates[key] = len(shapes)
            shapes.append(skeleton)
        columns[template_column].add(number)
        for c, j, item in sorted(found, key=lambda f: (f[0], f[1])):
            columns[c].add(item, (number, j))
    # numbered as first used, or the most used first (shorter numbers), whichever is smaller
    numbers = columns[template_column].values
    order = sorted(range(len(shapes)), key=Counter(numbers).__getitem__, reverse=True)
    rank = {t: r for r, t in enumerate(order)}
    ranked = [rank[t] for t in numbers]
    if _size(ranked) < _size(numbers):
        shapes = [shapes[t] for t in order]
        columns[template_column].values = ranked
    parts = [c.encoded() for c in columns]
    header = {"events": len(events), "templates": shapes, "columns": [about for about, _ in parts],
              "template": template_column, "seq": seq_column}
    head = json.dumps(header, separators=(",", ":"), allow_nan=False).encode("ascii")
    block = len(head).to_bytes(4, "little") + head + b"".join(data for _, data in parts)
    return block, columns[template_column].values


def decode(block: bytes) -> list[dict[str, Any]]:
    """Every event's record rebuilt from :func:`encode`'s block (as ``json.loads`` of
    its line gives it)."""
    return decoded(block)[0]


def decoded(block: bytes) -> tuple[list[dict[str, Any]], list[int]]:
    """:func:`decode`'s records and each event's template number."""
    size = int.from_bytes(block[:4], "little")
    header = json.loads(block[4:4 + size].decode("utf-8"))
    at = 4 + size
    values: list[list[Any]] = []
    for about in header["columns"]:
        count = about["count"]
        if about["type"] == "f":
            column = list(struct.unpack_from(f"<{count}d", block, at))
            at += 8 * count
        else:
            column, at = _read_varints(block, at, count)
            if about["type"] == "s":
                column = [about["strings"][k] for k in column]
            elif about["delta"] == 1:
                total = 0
                for k, gap in enumerate(column):
                    total += gap
                    column[k] = total
        values.append(column)
    templates = header["templates"]
    order = values[header["template"]]
    counts = [Counter(int(p[1:].split(".")[0]) for p in _marks(t)) for t in templates]
    again = [c for c, about in enumerate(header["columns"]) if about.get("delta") == 2]
    if again:  # each value less the one before at its template's place
        cursor = [0] * len(values)
        last: dict[tuple, int] = {}
        for t in order:
            for c, n in counts[t].items():
                if c in again:
                    for j in range(n):
                        values[c][cursor[c] + j] += last.get((c, t, j), 0)
                        last[(c, t, j)] = values[c][cursor[c] + j]
                cursor[c] += n
    for c, about in enumerate(header["columns"]):
        if about["type"] == "d":
            values[c] = [n / 10 ** about["scale"] for n in values[c]]
    cursor = [0] * len(values)
    records = []

    def fill(item: Any, base: dict[int, int]) -> Any:
        if isinstance(item, dict):
            return {k: fill(v, base) for k, v in item.items()}
        if isinstance(item, list):
            return [fill(v, base) for v in item]
        if isinstance(item, str) and item.startswith(MARK):
            c, j = map(int, item[1:].split("."))
            return values[c][base[c] + j]
        return item

    seq_column = header["seq"]
    for i in range(header["events"]):
        t = order[i]
        kind, transition, agent, data, time = templates[t]
        base = {c: cursor[c] for c in counts[t]}
        records.append({"agent": agent, "data": fill(data, base), "kind": kind,
                        "seq": i if seq_column is None else values[seq_column][i],
                        "time": fill(time, base), "transition": transition})
        for c, n in counts[t].items():
            cursor[c] += n
    return records, list(values[header["template"]])


def _marks(item: Any):
    """The placeholders in a template."""
    if isinstance(item, dict):
        for v in item.values():
            yield from _marks(v)
    elif isinstance(item, list):
        for v in item:
            yield from _marks(v)
    elif isinstance(item, str) and item.startswith(MARK):
        yield item
