"""The cost of watching a run live: ``petriflow run --live`` with a page following it.

The 20-robot bidding mission (``nets/bidding/bidding-autonomous-20.yaml``, its
``run-20.yaml``) is run alternately without ``--live`` and with ``--live`` and a client
following the page's WebSocket (it receives the snapshot and every update, at most 20
a second: what the page receives; the browser's own work is in another process and
is not the run's). Each run is a process of its own; its CPU time (user + system, from
``wait4``) is compared, pair by pair, so both sides of a pair met the same load.

Then a page opened mid-run: the time from connecting to the snapshot (the current
marking) arriving, over the WebSocket; with ``--browser`` also in headless Chromium
(from navigation to the marking shown).

Run: ``python bench/live.py [--pairs 3] [--until 60] [--browser]``. Prints Markdown.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NET = ROOT / "nets" / "bidding" / "bidding-autonomous-20.yaml"
CONFIG = ROOT / "nets" / "bidding" / "run-20.yaml"
RUN = [sys.executable, "-c", "import sys; from petriflow.cli import main; sys.exit(main())", "run", str(NET),
       "--config", str(CONFIG), "--quiet"]


def cpu_of(process: subprocess.Popen) -> float:
    """Wait for ``process``; its CPU seconds (user + system)."""
    _, status, usage = os.wait4(process.pid, 0)
    process.returncode = os.waitstatus_to_exitcode(status)
    return usage.ru_utime + usage.ru_stime


def follow(url: str, counts: dict) -> None:
    """A client that follows the live page's WebSocket to the end (what a page receives)."""
    from websockets.sync.client import connect

    target = url.replace("http://", "ws://").replace("/?token=", "/ws?token=")
    started = time.perf_counter()
    with connect(target, max_size=2 ** 26, open_timeout=30) as socket:
        first = json.loads(socket.recv())
        counts["snapshot_s"] = time.perf_counter() - started
        counts["snapshot_bytes"] = len(json.dumps(first))
        try:
            for message in socket:
                counts["updates"] = counts.get("updates", 0) + 1
                counts["bytes"] = counts.get("bytes", 0) + len(message)
        except Exception:  # noqa: BLE001 - the run ended and closed the connection
            pass


def live_url(stderr: Path, process: subprocess.Popen) -> str:
    while True:
        found = re.search(r"live page: (http://\S+)", stderr.read_text())
        if found:
            return found.group(1)
        if process.poll() is not None:
            raise SystemExit(f"the live run ended early: {stderr.read_text()}")
        time.sleep(0.05)


def one(until: float, live: bool, folder: Path, delay: float = 0.0) -> dict:
    """One run; ``live``: with ``--live`` and a follower (connecting after ``delay`` s)."""
    stderr = folder / f"stderr-{time.monotonic_ns()}.txt"
    with open(stderr, "w") as err:
        process = subprocess.Popen([*RUN, "--until", str(until), *(["--live", "0"] if live else [])],
                                   stdout=subprocess.DEVNULL, stderr=err)
        counts: dict = {}
        follower = None
        if live:
            url = live_url(stderr, process)
            time.sleep(delay)
            follower = threading.Thread(target=follow, args=(url, counts))
            follower.start()
        cpu = cpu_of(process)
        if follower is not None:
            follower.join(timeout=60)
    if process.returncode not in (0, 1):
        raise SystemExit(f"the run failed: {stderr.read_text()}")
    counts["cpu"] = cpu
    return counts


def browser_open(until: float, folder: Path, delay: float) -> float:
    """Seconds from navigating to a live page mid-run to its marking shown, in Chromium."""
    import shutil

    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium")
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage"):
        options.add_argument(argument)
    driver = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)
    stderr = folder / "browser-run.txt"
    try:
        with open(stderr, "w") as err:
            process = subprocess.Popen([*RUN, "--until", str(until), "--live", "0"], stdout=subprocess.DEVNULL,
                                       stderr=err)
            url = live_url(stderr, process)
            time.sleep(delay)
            driver.get(url)
            while not driver.execute_script("return window.pfLive && window.pfLive.ready"):
                time.sleep(0.02)
            shown = driver.execute_script("return window.pfLive.readyMs") / 1000
            marked = driver.execute_script("return Object.keys(window.pfLive.shownMarking()).length")
            process.wait()
        print(f"browser: page ready with {marked} places marked, {shown:.2f} s after navigation")
        return shown
    finally:
        driver.quit()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--until", type=float, default=60.0, help="simulated seconds of each run")
    parser.add_argument("--browser", action="store_true", help="also open the page mid-run in Chromium")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="petriflow-bench-live-") as name:
        folder = Path(name)
        rows = []
        for k in range(args.pairs):
            plain = one(args.until, False, folder)
            live = one(args.until, True, folder, delay=1.0 + k)
            rows.append((plain["cpu"], live["cpu"], live))
            print(f"pair {k + 1}: without {plain['cpu']:.2f} s CPU, with --live {live['cpu']:.2f} s"
                  f" ({live['cpu'] / plain['cpu']:.3f}); {live.get('updates', 0)} updates,"
                  f" {live.get('bytes', 0) / 1e6:.1f} MB; snapshot mid-run {live['snapshot_s'] * 1000:.0f} ms,"
                  f" {live['snapshot_bytes'] / 1e3:.0f} kB", flush=True)
        ratios = [b / a for a, b, _ in rows]
        print()
        print(f"`python bench/live.py --pairs {args.pairs} --until {args.until:g}`"
              f" (20-robot bidding mission, {args.until:g} s simulated per run)")
        print()
        print("| | CPU without --live (s) | CPU with --live + follower (s) | ratio | snapshot mid-run |")
        print("|---|---|---|---|---|")
        for k, (a, b, live) in enumerate(rows, 1):
            print(f"| pair {k} | {a:.2f} | {b:.2f} | {b / a:.3f} | {live['snapshot_s'] * 1000:.0f} ms |")
        print(f"| median | {statistics.median(a for a, _, _ in rows):.2f} |"
              f" {statistics.median(b for _, b, _ in rows):.2f} | {statistics.median(ratios):.3f} | |")
        if args.browser:
            browser_open(args.until, folder, delay=3.0)


if __name__ == "__main__":
    main()
