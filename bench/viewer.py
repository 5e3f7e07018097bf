"""How fast a run's page opens and how smoothly its slider moves, in headless Chromium.

    python bench/viewer.py PAGE.html [--repeat 3]

For each repeat, a fresh browser opens the page from disk and reports: the time from
the start of navigation until the page is ready (trace inflated, indexed, first
instant drawn), the page script's own part of it, then the time one slider move takes
(every panel redrawn and the layout it forces, over 100 moves spread over the run),
and the frame intervals while it plays at 20x (60 s of simulated time in 3 s). Wall
times depend on the machine's load; beside them, the CPU time the page's renderer
process spent (Chromium's own ``ProcessTime`` and main-thread ``ThreadTime`` metrics),
which a busy machine distorts much less: to get ready, per slider move, per frame played.
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import time
from pathlib import Path

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

PLAY = """
const done = arguments[arguments.length - 1];
document.getElementById('speed').value = '20';
window.pfView.setIndex(0);
const gaps = []; let last = null; const start = performance.now();
function frame(now) {
  if (last !== null) gaps.push(now - last);
  last = now;
  if (now - start < 3000) requestAnimationFrame(frame); else { document.getElementById('b-play').click(); done(gaps); }
}
document.getElementById('b-play').click();
requestAnimationFrame(frame);
"""


def cpu(driver) -> dict:
    """The renderer's CPU seconds so far: ``ProcessTime`` (the process), ``ThreadTime`` (its main thread)."""
    metrics = {m["name"]: m["value"] for m in driver.execute_cdp_cmd("Performance.getMetrics", {})["metrics"]}
    return {"ProcessTime": metrics["ProcessTime"], "ThreadTime": metrics["ThreadTime"]}


def measure(page: Path) -> dict:
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or shutil.which("google-chrome")
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--window-size=1500,1900"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    driver.set_script_timeout(120)
    try:
        driver.execute_cdp_cmd("Performance.enable", {})
        driver.get(page.resolve().as_uri())
        while not driver.execute_script("return !!(window.pfView && window.pfView.ready)"):
            time.sleep(0.02)
        ready = driver.execute_script("return window.pfView.readyAt")
        script = driver.execute_script("return window.pfView.loadMs")
        opened = cpu(driver)
        moves = driver.execute_script("return window.pfView.bench(100)")
        moved = cpu(driver)
        gaps = driver.execute_async_script(PLAY)
        played = cpu(driver)
        return {"ready_ms": ready, "script_ms": script, "ready_cpu_ms": 1000 * opened["ProcessTime"],
                "move_mean_ms": moves["mean"], "move_p95_ms": moves["p95"],
                "move_cpu_ms": 10 * (moved["ThreadTime"] - opened["ThreadTime"]),
                "frame_median_ms": statistics.median(gaps), "frame_p95_ms": sorted(gaps)[int(len(gaps) * 0.95)],
                "frame_cpu_ms": 1000 * (played["ProcessTime"] - moved["ProcessTime"]) / max(1, len(gaps)),
                "events": driver.execute_script("return window.pfView.count")}
    finally:
        driver.quit()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("page", type=Path)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print(f"{args.page}: {args.page.stat().st_size / 1e6:.2f} MB; load average {os.getloadavg()[0]:.1f}"
          f" on {os.cpu_count()} CPUs")
    for _ in range(args.repeat):
        result = measure(args.page)
        print("  " + ", ".join(f"{k} {v:.1f}" if isinstance(v, float) else f"{k} {v}" for k, v in result.items()))


if __name__ == "__main__":
    main()
