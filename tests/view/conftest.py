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
