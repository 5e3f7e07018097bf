"""The live page in a real browser (headless Chromium through Selenium): one test per
control, each on a run of its own, driven by the page's buttons as a person would;
the trace of each steered run replays to the marking the run ended with.

Slow (a run and a browser each): CI runs them (``-m slow``).
"""

from __future__ import annotations

import shutil
import time

import pytest

from petriflow.runtime.replay import markings
from petriflow.runtime.trace import read_trace

pytest.importorskip("selenium", reason="the browser tests need Selenium (pip install selenium)")
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
DRIVER = shutil.which("chromedriver")
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(BROWSER is None or DRIVER is None,
                                 reason="no headless browser: install Debian's chromium and chromium-driver"
                                 " (scripts/setup.sh does)")]


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1400,1200"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def until(driver, script: str, what: str, timeout: float = 60) -> object:
    """Wait until ``script`` (JavaScript returning a value) is truthy; its value."""
    deadline = time.monotonic() + timeout
    while True:
        value = driver.execute_script(script)
        if value:
            return value
        errors = driver.find_elements(By.ID, "error")
        assert not errors, errors[0].text
        assert time.monotonic() < deadline, f"{what}: not within {timeout:g} s"
        time.sleep(0.05)


def open_live(driver, run) -> None:
    driver.get_log("browser")
    driver.get(run.url)
    until(driver, "return window.pfLive && window.pfLive.ready", "the page's snapshot")


def click(driver, ident: str) -> None:
    driver.find_element(By.ID, ident).click()


def fill(driver, ident: str, text: str) -> None:
    box = driver.find_element(By.ID, ident)
    box.clear()
    box.send_keys(text)


def reply(driver) -> str:
    return driver.find_element(By.ID, "c-reply").text


def shown(driver) -> dict:
    return driver.execute_script("return window.pfLive.shownMarking()")


def final_marking(run) -> dict:
    """The marking the run ended with (its stop event), checked against the trace's replay."""
    events = read_trace(run.trace)
    stop = events[-1]
    assert stop.kind == "stop"
    replayed = list(markings(events))[-1][1].to_dict()
    assert replayed == stop.data["marking"]
    return replayed


def resume_to_end(driver, run) -> dict:
    click(driver, "c-resume")
    until(driver, "return window.pfLive.stop", "the run's end on the page")
    run.finish()
    marking = final_marking(run)
    until(driver, "const m = window.pfLive.shownMarking(); return JSON.stringify(Object.keys(m).sort()"
          f".reduce((o, k) => (o[k] = m[k], o), {{}})) === '{_json(marking)}'", "the page showing the final marking")
    return marking


def _json(marking: dict) -> str:
    import json

    return json.dumps(dict(sorted(marking.items())), separators=(",", ":"))


def no_console_errors(driver) -> None:
    severe = [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]
    assert not severe, severe


def test_pause_then_step_one_firing(browser, live_run):
    """A run started paused waits; the page's step fires exactly one transition and pauses again."""
    run = live_run("--paused")
    open_live(browser, run)
    assert browser.execute_script("return window.pfLive.state") == "paused"
    assert shown(browser) == {"start": 3}
    click(browser, "c-step")
    until(browser, "return window.pfLive.running().length === 1", "one firing running")
    time.sleep(0.5)  # still paused: nothing else fires
    assert browser.execute_script("return window.pfLive.running()") == ["work"]
    assert shown(browser) == {"start": 2}
    assert browser.execute_script("return window.pfLive.state") == "paused"
    resume_to_end(browser, run)
    no_console_errors(browser)


def test_pause_button_holds_a_running_run(browser, live_run):
    """Pause from the page stops a run that is going (paced at real time), resume lets it end."""
    run = live_run("--realtime")
    open_live(browser, run)
    click(browser, "c-pause")
    until(browser, "return window.pfLive.state === 'paused'", "paused")
    time.sleep(0.5)  # the pause's own event reaches the page (at most 1/20 s later)
    held = browser.execute_script("return window.pfLive.time")
    time.sleep(1.5)
    assert browser.execute_script("return window.pfLive.time") == held  # the clock stopped
    click(browser, "c-speed-set")  # the page's speed field: 1x; then as fast as it goes
    fill(browser, "c-speed", "0")
    click(browser, "c-speed-set")
    until(browser, "return document.getElementById('c-reply').textContent.startsWith('speed')", "speed set")
    marking = resume_to_end(browser, run)
    assert marking == {"done": 3}


def paused_with_breakpoint(browser, live_run, spec: str):
    """A run started paused, its page open, with the breakpoint ``spec`` added on the page."""
    run = live_run("--paused")
    open_live(browser, run)
    fill(browser, "c-break", spec)
    click(browser, "c-break-add")
    until(browser, f"return window.pfLive.control.breakpoints.includes({spec!r})", "the breakpoint listed")
    return run


def test_breakpoint_on_a_transition(browser, live_run):
    """`transition fix` pauses the run before fix fires; the trace has no start of fix before the resume."""
    run = paused_with_breakpoint(browser, live_run, "transition fix")
    fill(browser, "c-place", "spare")
    click(browser, "c-inject")
    until(browser, "return (window.pfLive.shownMarking().spare || 0) === 1", "the token injected")
    click(browser, "c-resume")
    until(browser, "return window.pfLive.state === 'paused'", "paused by the breakpoint")
    assert "fix" not in browser.execute_script("return window.pfLive.running()")
    assert shown(browser).get("spare") == 1
    resume_to_end(browser, run)
    events = read_trace(run.trace)
    hit = next(e for e in events if e.kind == "control" and e.data["action"] == "hit")
    assert hit.transition == "fix" and hit.data["spec"] == "transition fix"
    after = events[hit.seq + 1:]
    resumed = next(e for e in after if e.kind == "control" and e.data["action"] == "resume")
    assert not [e for e in after if e.seq < resumed.seq and e.kind == "start"]
    assert any(e.kind == "start" and e.transition == "fix" for e in after)


def test_breakpoint_on_a_place_count(browser, live_run):
    """`place done >= 2` pauses the run when done reaches 2, before any later firing."""
    run = paused_with_breakpoint(browser, live_run, "place done >= 2")
    click(browser, "c-resume")
    until(browser, "return window.pfLive.state === 'paused' && (window.pfLive.shownMarking().done || 0) === 2",
          "paused at done = 2")
    resume_to_end(browser, run)
    events = read_trace(run.trace)
    hit = next(e for e in events if e.kind == "control" and e.data["action"] == "hit")
    assert hit.data["tokens"] == 2
    resumed = next(e for e in events[hit.seq:] if e.kind == "control" and e.data["action"] == "resume")
    assert not [e for e in events[hit.seq:resumed.seq] if e.kind == "start"]


def test_inject_and_remove_tokens(browser, live_run):
    """Tokens put in and taken out from the page show at once and are in the trace's replay."""
    run = live_run("--paused")
    open_live(browser, run)
    fill(browser, "c-place", "spare")
    fill(browser, "c-count", "2")
    click(browser, "c-inject")
    until(browser, "return (window.pfLive.shownMarking().spare || 0) === 2", "two tokens injected")
    fill(browser, "c-place", "start")
    fill(browser, "c-count", "1")
    click(browser, "c-remove")
    until(browser, "return (window.pfLive.shownMarking().start || 0) === 2", "one token removed")
    fill(browser, "c-count", "9")
    click(browser, "c-remove")
    until(browser, "return document.getElementById('c-reply').textContent.startsWith('refused')", "refused")
    assert "holds 2 tokens, not 9" in reply(browser)
    marking = resume_to_end(browser, run)
    assert marking == {"done": 4}  # two work firings and two fix firings


def test_force_failed_takes_the_failure_route(browser, live_run):
    """Forcing a running firing to fail makes the net's failure route fire (work -> bad)."""
    run = live_run("--paused")
    open_live(browser, run)
    click(browser, "c-step")
    until(browser, "return window.pfLive.running().length === 1", "work running")
    until(browser, "return document.getElementById('c-firing').options.length === 1", "the firing listed")
    Select(browser.find_element(By.ID, "c-outcome")).select_by_value("failed")
    click(browser, "c-force")
    until(browser, "return (window.pfLive.shownMarking().bad || 0) === 1", "the failure route's token")
    marking = resume_to_end(browser, run)
    assert marking == {"bad": 1, "done": 2}
    end = next(e for e in read_trace(run.trace) if e.kind == "end")
    assert end.data["outcome"] == "failed" and end.data["reason"] == "forced failed by page"
