"""The cost of watching a run live: ``petriflow run --live`` with a page following it.

The 20-robot bidding mission (``nets/bidding/bidding-autonomous-20.yaml``, its
``run-20.yaml``) is run alternately without ``--live`` and with ``--live`` and a client
that loads the page (the server draws it then) and follows its WebSocket (it receives
the snapshot and every update, at most 20 a second: what a page asks of the run's
process; the browser's own work is in another process and is not the run's). Each run is a process of its own; its CPU time (user + system, from
``wait4``) is compared, pair by pair, so both sides of a pair met the same load.

Then a page opened mid-run: the time from connecting to the snapshot (the current
marking) arriving, over the WebSocket; with ``--browser`` also in headless Chromium
(from navigation to the marking shown).

With ``--memory SECONDS`` instead: one run watched for SECONDS of wall time by the page
in Chromium, open from the start, its JS heap sampled (before and after a garbage
collection, through the DevTools protocol) every ``--every`` seconds; start, end and
largest are printed. The page takes at most 20 updates a second of wall time whatever
the run does, so it cannot be fed an hour of updates in less than an hour; what can be
compressed is the events: the run is a net that never ends and sends the page about
2,000 lines a second, more than ten times the 20-robot mission's rate (``--mission``
watches the mission itself, which ends after about 190 s simulated, a minute of wall
time), so ten minutes of it hold more events than an hour of the mission.

``--paced`` instead runs that net at 1 s a firing kept to the wall clock: a real hour of
updates and events (about 120 lines a second) at little CPU.

Run: ``python bench/live.py [--pairs 3] [--until 60] [--browser]`` or
``python bench/live.py --memory 600 [--every 30] [--mission | --paced]``. Prints Markdown.
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
    """A client that loads the live page (the server draws it then) and follows its
    WebSocket to the end: what a page asks of the run's process."""
    from urllib.request import urlopen

    from websockets.sync.client import connect

    target = url.replace("http://", "ws://").replace("/?token=", "/ws?token=")
    started = time.perf_counter()
    with urlopen(url, timeout=60) as response:
        counts["page_bytes"] = len(response.read())
    counts["page_s"] = time.perf_counter() - started
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
    if live and "snapshot_s" not in counts:
        raise SystemExit("the follower never received the page's snapshot: the run ended before it connected"
                         " (a longer --until, or a machine less loaded)")
    counts["cpu"] = cpu
    return counts


def browser_open(until: float, folder: Path, delay: float) -> float:
    """Seconds from navigating to a live page mid-run to its marking shown, in Chromium."""
    driver = chromium()
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
            held = driver.execute_script("return Object.keys(window.pfLive.marking()).length")
            process.wait()
        print(f"browser: page ready {shown:.2f} s after navigation, showing tokens in {marked} of the picture's"
              f" places or agents' boxes (a folded net: one box per agent); {held} places marked in the snapshot")
        return shown
    finally:
        driver.quit()


def chromium():
    """Headless Chromium through Selenium (Debian's chromium and chromium-driver)."""
    import shutil

    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium")
    for argument in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                     "--window-size=1400,1000"):
        options.add_argument(argument)
    return webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=options)


def heap(driver) -> tuple[float, float]:
    """The page's JavaScript heap in use, MB: as it is, and after a full garbage collection
    (what the page holds on to)."""
    def used() -> float:
        metrics = driver.execute_cdp_cmd("Performance.getMetrics", {})["metrics"]
        return next(m["value"] for m in metrics if m["name"] == "JSHeapUsedSize") / 1e6

    raw = used()
    driver.execute_cdp_cmd("HeapProfiler.collectGarbage", {})
    return raw, used()


#: A net that never ends and makes events as fast as it can: sixty transitions, each
#: firing again and again (a 10 ms action), about 2,000 lines a second for the page.
def busy(seconds: float) -> str:
    """A net that never ends: 60 transitions, each waiting ``seconds`` then firing again."""
    return ("petriflow: 1\nplaces: [" + ", ".join(f"{{id: p{i}, tokens: 1}}" for i in range(60)) + "]\ntransitions:\n"
            + "".join(f"- {{id: t{i}, action: core.wait, params: {{seconds: {seconds}}}, in: [p{i}], out: [p{i}]}}\n"
                      for i in range(60)))


def memory(seconds: float, every: float, folder: Path, mission: bool, paced: bool = False) -> None:
    """The page's memory over a long run: the page open from the start for ``seconds`` of
    wall time (or until the run ends), its JS heap sampled every ``every`` s. The run is
    the 20-robot mission (``mission``; it ends after about 190 s simulated) or a net that
    never ends and sends the page more events a second than the mission does; ``paced``: that
    net's transitions wait 1 s each and the run keeps to the wall clock (``--realtime``), so
    a run of an hour is an hour of simulated time at little CPU."""
    if mission:
        command = [*RUN, "--until", "1e9", "--live", "0"]
    else:
        (folder / "busy.yaml").write_text(busy(1.0 if paced else 0.01))
        command = [sys.executable, "-c", "import sys; from petriflow.cli import main; sys.exit(main())", "run",
                   str(folder / "busy.yaml"), "--until", "1e9", "--quiet", "--live", "0",
                   *(["--realtime"] if paced else [])]
    driver = chromium()
    stderr = folder / "memory-run.txt"
    samples = []
    try:
        with open(stderr, "w") as err:
            process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=err)
            try:
                driver.get(live_url(stderr, process))
                driver.execute_cdp_cmd("Performance.enable", {})
                started = time.monotonic()
                while not driver.execute_script("return window.pfLive && window.pfLive.ready"):
                    time.sleep(0.05)
                while True:
                    state = driver.execute_script("const l = window.pfLive; return [l.time, l.updates, l.received,"
                                                  " l.events, !!l.stop]")
                    raw, kept = heap(driver)
                    samples.append((time.monotonic() - started, *state[:4], raw, kept))
                    print(f"  {samples[-1][0]:7.1f} s wall, t = {state[0]:7.1f} s: {state[1]} updates,"
                          f" {state[2]} events received, {state[3]} held; heap {raw:.2f} MB, {kept:.2f} MB"
                          " after GC", flush=True)
                    if state[4] or process.poll() is not None or samples[-1][0] >= seconds:
                        break
                    time.sleep(every)
            finally:
                if process.poll() is None:
                    process.kill()
                process.wait()
    finally:
        driver.quit()
    kept = [s[6] for s in samples]
    print()
    what = ("the 20-robot bidding mission" if mission else "a net of 60 transitions of 1 s each, in real time"
            if paced else "a net of 60 transitions firing as fast as they can")
    flag = " --mission" if mission else " --paced" if paced else ""
    print(f"`python bench/live.py --memory {seconds:g} --every {every:g}{flag}` ({what},"
          f" page open from the start, {samples[-1][0]:.0f} s of wall time)")
    print()
    print("| | wall (s) | simulated (s) | updates | events received | events held | JS heap after GC (MB) |")
    print("|---|---|---|---|---|---|---|")
    first, last = samples[0], samples[-1]
    top = max(samples, key=lambda s: s[6])
    for name, row in (("start", first), ("end", last), ("max", top)):
        print(f"| {name} | {row[0]:.0f} | {row[1]:.0f} | {row[2]} | {row[3]} | {row[4]} | {row[6]:.2f} |")
    print(f"\nheap after GC: start {kept[0]:.2f} MB, end {kept[-1]:.2f} MB, max {max(kept):.2f} MB;"
          f" in use (no GC) at most {max(s[5] for s in samples):.2f} MB")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--until", type=float, default=60.0, help="simulated seconds of each run")
    parser.add_argument("--browser", action="store_true", help="also open the page mid-run in Chromium")
    parser.add_argument("--memory", type=float, metavar="SECONDS",
                        help="instead: the page's JS heap over SECONDS of wall time of one run (Chromium)")
    parser.add_argument("--every", type=float, default=10.0, help="with --memory: wall seconds between samples")
    parser.add_argument("--mission", action="store_true",
                        help="with --memory: the 20-robot mission (it ends after ~190 s simulated) instead of a net"
                             " that never ends")
    parser.add_argument("--paced", action="store_true",
                        help="with --memory: the net that never ends, 1 s a firing, kept to the wall clock (an hour's run)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="petriflow-bench-live-") as name:
        folder = Path(name)
        if args.memory:
            memory(args.memory, args.every, folder, args.mission, args.paced)
            return
        rows = []
        for k in range(args.pairs):
            plain = one(args.until, False, folder)
            live = one(args.until, True, folder, delay=1.0 + 0.5 * (k % 3))  # opened early, while the run goes on
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
