"""Run every shipped net (``petriflow run NET --trace``) and print each trace's SHA-256.

A refactoring that must not change behaviour keeps every digest: save them before
(``python scripts/trace_digests.py > before.json``), compare after
(``python scripts/trace_digests.py --compare before.json``: exit 1 and the nets whose
trace, exit code or message changed).

Nets that a run refuses (a cycle of instant transitions, say) are recorded by their exit
code and the digest of their standard error.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
NETS = REPO / "nets"


def shipped_nets() -> list[Path]:
    """The nets under nets/ (YAML with a ``petriflow:`` key, PNML), experiments left out."""
    found = []
    for path in sorted(NETS.rglob("*")):
        if "experiments" in path.parts:
            continue
        if path.suffix == ".pnml" or (path.suffix in (".yaml", ".yml") and any(
                line.startswith("petriflow:") for line in path.read_text().splitlines())):
            found.append(path)
    return found


def digest(net: Path) -> dict:
    with tempfile.TemporaryDirectory() as folder:
        trace = Path(folder) / "t.jsonl"
        done = subprocess.run([sys.executable, "-m", "petriflow.cli", "run", str(net), "--trace", str(trace),
                               "--quiet"], capture_output=True, text=True)
        entry = {"exit": done.returncode}
        if trace.exists():
            entry["trace"] = hashlib.sha256(trace.read_bytes()).hexdigest()
        else:  # the message, with the checkout's own folder left out (it names the net's path)
            entry["stderr"] = hashlib.sha256(done.stderr.replace(str(REPO), "").encode()).hexdigest()
        return entry


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", metavar="BEFORE.json", help="compare with digests saved before")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    nets = shipped_nets()
    with ThreadPoolExecutor(args.workers) as pool:
        digests = dict(zip((str(n.relative_to(NETS)) for n in nets), pool.map(digest, nets)))
    if args.compare is None:
        json.dump(digests, sys.stdout, indent=1, sort_keys=True)
        print()
        return 0
    before = json.loads(Path(args.compare).read_text())
    changed = sorted(n for n in set(before) | set(digests) if before.get(n) != digests.get(n))
    for name in changed:
        print(f"changed: {name}: {before.get(name)} -> {digests.get(name)}")
    print(f"{len(digests) - len(changed)} of {len(digests)} nets give the same trace")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
