"""The viewer's pages in a real browser: headless Chromium driven by Selenium through
chromedriver (scripts/setup.sh installs Debian's chromium and chromium-driver).

Each test opens a page from disk, moves the slider to an event and checks that the
marking the net shows is the one ``petriflow replay --at N`` computes, filters the
event list by an agent, clicks an event, and finds no error in the browser's console.
A screenshot of each page is written next to the test's files (and into
``$PETRIFLOW_VIEW_SCREENSHOTS`` when that names a folder).
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import pytest

import petriflow
from petriflow.examples import folder as nets_folder
from petriflow.runtime.replay import markings
from petriflow.runtime.trace import read_trace

selenium = pytest.importorskip("selenium", reason="the browser tests need Selenium (pip install selenium)")
from selenium import webdriver  # noqa: E402
from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402
from selenium.webdriver.support.ui import Select  # noqa: E402

BROWSER = next((shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome") if shutil.which(n)), None)
DRIVER = shutil.which("chromedriver")
pytestmark = pytest.mark.skipif(BROWSER is None or DRIVER is None,
                                reason="no headless browser: install Debian's chromium and chromium-driver"
                                " (scripts/setup.sh does)")


@pytest.fixture(scope="module")
def browser():
    options = webdriver.ChromeOptions()
    options.binary_location = BROWSER
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1500,1900", "--allow-file-access-from-files"):
        options.add_argument(argument)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(DRIVER), options=options)
    driver.set_script_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()


def open_page(driver, page: Path) -> None:
    driver.get_log("browser")  # forget what came before
    driver.get(page.resolve().as_uri())
    deadline = time.monotonic() + 60
    while not driver.execute_script("return !!(window.pfView && window.pfView.ready)"):
        errors = driver.find_elements(By.ID, "error")
        assert not errors, errors[0].text
        assert time.monotonic() < deadline, "the page did not get ready in 60 s"
        time.sleep(0.05)


def console_errors(driver) -> list[str]:
    return [entry["message"] for entry in driver.get_log("browser") if entry["level"] == "SEVERE"]


def screenshot(driver, tmp_path: Path, name: str) -> Path:
    shot = tmp_path / f"{name}.png"
    driver.save_screenshot(str(shot))
    assert shot.stat().st_size > 10_000
    folder = os.environ.get("PETRIFLOW_VIEW_SCREENSHOTS")
    if folder:
        Path(folder).mkdir(parents=True, exist_ok=True)
        shutil.copy(shot, Path(folder) / shot.name)
    return shot


def records(driver) -> list[dict]:
    """Every event's record as the open page rebuilds it from its columns."""
    text = driver.execute_script("const out = []; for (let i = 0; i < window.pfView.count; i++)"
                                 " out.push(JSON.stringify(window.pfView.record(i))); return out.join('\\n');")
    return [json.loads(line) for line in text.split("\n")]


def move_slider(driver, n: int) -> None:
    """As a user drags it: the range input's value changes and it fires ``input``."""
    driver.execute_script("const s = document.getElementById('slider'); s.value = arguments[0];"
                          " s.dispatchEvent(new Event('input', {bubbles: true}));", n)


@pytest.mark.parametrize("which, net, agent", [
    ("smart_trace", "smart/smart.yaml", "robot3l"),
    ("bidding_trace", "bidding/bidding-autonomous-2.yaml", "robot2"),
])
def test_run_page_replays_the_trace(browser, which, net, agent, request, tmp_path):
    trace = request.getfixturevalue(which)
    events = read_trace(trace)
    page = petriflow.view(trace, net=nets_folder() / net, out=tmp_path / "run.html")
    open_page(browser, page)
    assert browser.execute_script("return window.pfView.count") == len(events)
    assert records(browser) == [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    assert browser.find_elements(By.CSS_SELECTOR, "#net svg g.node")  # the net is drawn
    after = [m.to_dict() for _, m in markings(events)]
    for n in (len(events) // 3, (2 * len(events)) // 3, len(events) - 1):
        move_slider(browser, n)
        assert browser.execute_script("return window.pfView.index") == n
        shown = browser.execute_script("return window.pfView.shownMarking()")
        assert shown == after[n], f"the marking shown after event {n}"
        assert browser.find_element(By.ID, "now").text.startswith(f"event {n} ")
    # step buttons and the keyboard move one event
    browser.find_element(By.ID, "b-prev").click()
    assert browser.execute_script("return window.pfView.index") == len(events) - 2
    assert browser.execute_script("return window.pfView.shownMarking()") == after[len(events) - 2]
    # the agent filter keeps that agent's events only, all of them
    Select(browser.find_element(By.ID, "f-agent")).select_by_value(agent)
    listed = browser.execute_script("return window.pfView.filtered()")
    assert listed == [i for i, e in enumerate(events) if e.agent == agent]
    rows = browser.execute_script("return window.pfView.listed()")
    assert rows and all(r["agent"] == agent for r in rows)
    # clicking an event moves the slider there
    browser.execute_script("document.getElementById('events').scrollTop = 0;")
    time.sleep(0.1)
    shown = [r for r in browser.find_elements(By.CSS_SELECTOR, "#events .row") if r.is_displayed()]
    row = sorted(shown, key=lambda r: int(r.get_attribute("data-index")))[1]
    index = int(row.get_attribute("data-index"))
    row.click()
    assert browser.execute_script("return window.pfView.index") == index
    assert int(browser.find_element(By.ID, "slider").get_attribute("value")) == index
    assert f'"seq": {events[index].seq}' in browser.find_element(By.ID, "event-detail").text
    # the world is drawn from the trace's poses
    assert browser.execute_script("return window.pfView.bodies") >= 2
    shot = screenshot(browser, tmp_path, f"view-{trace.stem}")
    assert shot.is_file()
    assert console_errors(browser) == []


def test_a_page_without_the_net_lists_the_places(browser, bidding_trace, tmp_path):
    events = read_trace(bidding_trace)
    page = petriflow.view(bidding_trace, out=tmp_path / "plain.html")
    open_page(browser, page)
    n = len(events) // 2
    move_slider(browser, n)
    assert browser.execute_script("return window.pfView.shownMarking()") == list(markings(events[: n + 1]))[-1][1].to_dict()
    assert browser.find_elements(By.CSS_SELECTOR, "#marking-list tr[data-place]")
    assert console_errors(browser) == []


def test_the_page_rebuilds_awkward_records_exactly(browser, awkward_events, tmp_path):
    trace = tmp_path / "awkward.jsonl"
    trace.write_text("".join(e.to_json() + "\n" for e in awkward_events), encoding="utf-8")
    open_page(browser, petriflow.view(trace, out=tmp_path / "awkward.html"))
    assert records(browser) == [json.loads(line) for line in trace.read_text(encoding="utf-8").splitlines()]
    move_slider(browser, 7)  # the list shows the rebuilt record
    detail = browser.find_element(By.ID, "event-detail").text
    assert '"name": "label 7"' in detail and '"mark": "\\u00010.0"' in detail
    assert console_errors(browser) == []


def test_sweep_page_draws_each_metric(browser, tmp_path):
    from petriflow.sweep import load_sweep, run_sweep

    folder = tmp_path / "s"
    folder.mkdir()
    (folder / "net.yaml").write_text("petriflow: 1\nplaces: [{id: i, tokens: 1}, o]\ntransitions:\n"
                                     "  - {id: t, action: core.wait, params: {seconds: 1}, in: [i], out: [o]}\n")
    (folder / "sweep.yaml").write_text(
        "petriflow-sweep: 1\nnet: net.yaml\ntrials: 2\nmatrix:\n  seconds: [1, 2, 3]\n"
        "set:\n  net.transitions.t.params.seconds: \"${seconds}\"\nmetrics:\n  time_s: core.end_time\n"
        "paper:\n  source: Table 0\n  rows:\n    - {params: {seconds: 2}, values: {time_s: 2.5}}\n")
    run_sweep(load_sweep(folder / "sweep.yaml"), workers=1, db=folder / "r.db")
    page = petriflow.view(folder / "r.db", out=tmp_path / "sweep.html")
    open_page(browser, page)
    assert browser.execute_script("return window.pfView.plots") == 1
    assert browser.find_elements(By.CSS_SELECTOR, ".plot canvas")  # dygraphs drew it
    cells = [td.text for td in browser.find_elements(By.CSS_SELECTOR, "#report td")]
    assert "2.5" in cells and "-0.5 (-20.0%)" in cells  # the paper, the deviation
    Select(browser.find_element(By.ID, "t-status")).select_by_value("ok")
    assert browser.find_element(By.ID, "t-count").text == "6 of 6 trials"
    screenshot(browser, tmp_path, "view-sweep")
    assert console_errors(browser) == []


def test_a_big_team_net_is_drawn_folded_and_a_click_opens_one_agents_subnet(browser, tmp_path):
    """Above the size ``export`` folds at, the net panel shows one box per agent (with the
    tokens inside it); clicking a box shows that agent's subnet in full with the marking,
    and "back" returns to the folded drawing."""
    from petriflow.fold import should_fold
    from petriflow.io import save_net
    from petriflow.runtime.session import run_files
    from tests.test_fold import team

    net = team(12)
    assert should_fold(net)
    source = tmp_path / "team.yaml"
    save_net(net, source, "yaml")
    trace = tmp_path / "team.jsonl"
    with pytest.warns(UserWarning, match="token game"):
        run_files(source, trace=trace, max_firings=40)
    events = read_trace(trace)
    page = petriflow.view(trace, net=source, out=tmp_path / "team.html")
    open_page(browser, page)
    boxes = browser.find_elements(By.CSS_SELECTOR, "#net g.node[data-agent]")
    assert len(boxes) == 12
    assert not browser.find_elements(By.CSS_SELECTOR, '#net g.node[data-place="r1_idle"]')  # folded inside r1
    move_slider(browser, len(events) - 1)
    after = list(markings(events))[-1][1].to_dict()
    r1 = browser.find_element(By.CSS_SELECTOR, '#net g.node[data-agent="agent:r1"]')
    inside = sum(n for p, n in after.items() if p.startswith("r1_"))
    assert int(r1.get_attribute("data-tokens")) == inside
    screenshot(browser, tmp_path, "view-team-folded")
    browser.execute_script("arguments[0].dispatchEvent(new MouseEvent('click', {bubbles: true}))", r1)
    deadline = time.monotonic() + 10
    while not browser.find_elements(By.CSS_SELECTOR, '#net g.node[data-place="r1_idle"]'):
        assert time.monotonic() < deadline, "r1's subnet did not open"
        time.sleep(0.05)
    shown = browser.execute_script("return window.pfView.shownMarking()")
    assert {p: n for p, n in shown.items() if p.startswith("r1_")} == \
        {p: n for p, n in after.items() if p.startswith("r1_")}
    screenshot(browser, tmp_path, "view-team-r1")
    browser.find_element(By.ID, "net-back").click()
    assert len(browser.find_elements(By.CSS_SELECTOR, "#net g.node[data-agent]")) == 12
    assert console_errors(browser) == []


def test_a_monitored_violation_leads_the_summary_and_is_red_in_the_events(browser, tmp_path):
    """`run --monitor` found a violation: the summary names it first, its row is red."""
    from petriflow.cli import main
    from tests.properties.test_monitor import RACE

    net = tmp_path / "race.yaml"
    net.write_text(RACE)
    trace = tmp_path / "race.jsonl"
    assert main(["run", str(net), "--monitor", "--trace", str(trace), "--quiet"]) == 1
    open_page(browser, petriflow.view(trace, out=tmp_path / "race.html"))
    assert browser.find_element(By.ID, "summary").text.startswith("VIOLATED property exclusive at event ")
    rows = [r for r in browser.find_elements(By.CSS_SELECTOR, "#events .row") if "VIOLATED" in r.text]
    assert len(rows) == 1 and "failed" in rows[0].get_attribute("class").split()
    assert console_errors(browser) == []
