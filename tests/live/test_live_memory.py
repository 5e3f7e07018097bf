"""The live page keeps what it holds bounded, in a real browser (headless Chromium): its
event list stays at the window however many events come, and opening a folded net's
subnets again and again adds no listener (each would keep the pictures it shows alive).

Slow (a run and a browser each): CI runs them (``-m slow``). The page's memory over a
long run is measured by ``python bench/live.py --memory`` (docs/benchmarks.md).
"""

from __future__ import annotations

import pytest

from tests.live.test_live_browser import browser, open_live, until  # noqa: F401 - the fixture

pytestmark = pytest.mark.slow

#: Sixty transitions, each firing again and again: a run that makes events as fast as it can.
BUSY = "petriflow: 1\nplaces: [" + ", ".join(f"{{id: p{i}, tokens: 1}}" for i in range(60)) + "]\ntransitions:\n" + \
    "".join(f"- {{id: t{i}, action: core.wait, params: {{seconds: 0.01}}, in: [p{i}], out: [p{i}]}}\n"
            for i in range(60))


def team(size: int = 40) -> str:
    """Two agents' chains of ``size`` steps each: above the size a page draws folded."""
    parts = []
    for agent in ("a", "b"):
        places = ", ".join(f"{{id: {agent}{i}, tokens: {int(i == 0)}}}" for i in range(size + 1))
        steps = "".join(f"      - {{id: {agent}t{i}, action: core.wait, params: {{seconds: 1}}, in: [{agent}{i}],"
                        f" out: [{agent}{i + 1}]}}\n" for i in range(size))
        parts.append(f"  - id: {agent}\n    agent: {agent}\n    places: [{places}]\n    transitions:\n{steps}")
    return "petriflow: 1\nsubnets:\n" + "".join(parts)


def test_the_page_keeps_only_its_window_of_events(browser, live_run):  # noqa: F811
    """Thousands of events reach the page; it holds at most its window of them."""
    run = live_run("--until", "1000000", net=BUSY)
    open_live(browser, run)
    window = browser.execute_script("return window.pfLive.window")
    assert window == 400
    until(browser, f"return window.pfLive.received > {10 * window}", "ten windows of events")
    held = browser.execute_script("return window.pfLive.events")
    assert window // 2 < held <= window


def listeners(driver, expression: str) -> int:
    """How many event listeners the object ``expression`` has (Chromium's DevTools protocol)."""
    found = driver.execute_cdp_cmd("Runtime.evaluate", {"expression": expression})["result"]["objectId"]
    return len(driver.execute_cdp_cmd("DOMDebugger.getEventListeners", {"objectId": found})["listeners"])


def test_opening_subnets_again_and_again_adds_no_listener(browser, live_run):  # noqa: F811
    """The folded net's boxes open their subnets (drawn by the server when asked) and close
    again, eight times: the window and the net panel have as many listeners as before."""
    run = live_run("--paused", net=team())
    open_live(browser, run)
    assert browser.execute_script("return document.querySelectorAll('#net g[data-agent]').length") == 2
    before = listeners(browser, "window"), listeners(browser, "document.getElementById('net')")
    for k in range(8):
        agent = "ab"[k % 2]
        browser.execute_script(f"""const g = document.querySelector('#net g[data-agent="agent:{agent}"]');
            g.dispatchEvent(new MouseEvent('mousedown')); g.dispatchEvent(new MouseEvent('click'));""")
        until(browser, "return document.getElementById('net-back')", f"agent {agent}'s subnet opened")
        assert browser.execute_script(f"return !!document.querySelector('#net g[data-transition=\"{agent}t0\"]')")
        browser.execute_script("document.getElementById('net-back').click()")
        until(browser, "return document.querySelectorAll('#net g[data-agent]').length === 2", "the folded net back")
    after = listeners(browser, "window"), listeners(browser, "document.getElementById('net')")
    assert after == before
    assert browser.execute_script("return window.pfLive.shownMarking()") == {"agent:a": 1, "agent:b": 1}
