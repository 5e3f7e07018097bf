"""Traces of short runs of shipped scenarios, for the viewer's tests (made once a session)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from petriflow.examples import folder

NETS = folder()


def run_trace(folder: Path, net: str, until: float, poses: float | None) -> Path:
    from petriflow.runtime.session import run_files

    trace = folder / (Path(net).stem + ".jsonl")
    run_files(NETS / net, trace=trace, until=until, poses=poses)
    return trace


@pytest.fixture(scope="session")
def smart_trace(tmp_path_factory) -> Path:
    """The SMART net's first seconds, poses every half second."""
    return run_trace(tmp_path_factory.mktemp("smart"), "smart/smart.yaml", until=4.0, poses=0.5)


@pytest.fixture(scope="session")
def bidding_trace(tmp_path_factory) -> Path:
    """Two bidding robots mapping an office for 20 s, poses every second."""
    return run_trace(tmp_path_factory.mktemp("bidding"), "bidding/bidding-autonomous-2.yaml", until=20.0, poses=1.0)


@pytest.fixture
def awkward_events() -> list:
    """Events with values a column must not change: floats no short decimal holds,
    integers past 2**50 (exact in a browser too), strings that look like placeholders,
    many different strings at one place, integer-like keys, nested lists, nulls and
    booleans, irregular times, ``seq`` other than the event's position."""
    from petriflow.runtime.trace import Event
    from petriflow.view.columns import MARK

    events = [Event(0, 0.0, "run", data={"marking": {"i": 2}, "agents": ["a", "b"], "dt": 0.1, "net": "n",
                                         "seed": 7})]
    for k in range(1, 700):
        events.append(Event(2 * k, 0.1 * k, "custom", "t", "a" if k % 2 else None, {
            "name": f"label {k}",                                   # a different string each time
            "firing": k, "x": 0.1 + 0.2 * k, "y": 1e-7 * k, "z": -0.0 if k == 5 else k / 3,
            "big": 2 ** 53 - k, "neg": -k, "flag": k % 3 == 0, "none": None,
            "mark": MARK + "0.0" if k % 7 == 0 else "plain", "odd": "\ud800 half a pair" if k == 3 else "",
            "keys": {"10": k, "2": [k, [k * 0.5, "s"]], "é ✓": {"deep": [1.5, 2.25, k]}},
            "list": list(range(k % 6)), "huge": 1.5e300, "tiny": 5e-324}))
    events.append(Event(1400, 1e9 + 0.123456789, "stop", data={"reason": "final", "firings": 1,
                                                               "marking": {}}))
    return events


def _page_data(page: Path) -> dict:
    """The JSON a page carries in its ``#pf-data`` block."""
    text = page.read_text(encoding="utf-8")
    match = re.search(r'<script type="application/json" id="pf-data">(.*?)</script>', text, re.S)
    assert match, "the page has no data block"
    return json.loads(match.group(1))


@pytest.fixture
def page_data():
    """Reads the data block of a page."""
    return _page_data
