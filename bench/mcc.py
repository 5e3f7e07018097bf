"""``check --properties`` on Model Checking Contest models: verdicts right, wrong, undecided.

For each model folder under ``--models`` (as the contest ships them: ``model.pnml`` and
the seven property files ``ReachabilityCardinality.xml`` ... ``LTLFireability.xml``),
each of the seven categories is decided by
:func:`petriflow.properties.check.check_properties` in a fresh forked process with a
budget of ``--budget`` CPU seconds (default 60: the contest's 16 formulas of one
category together; ``RLIMIT_CPU`` stops the process, and a wall-clock limit, ``--wall``,
default ten times the budget, guards a machine too loaded to give it that CPU). A process stopped by
the budget leaves its 16 properties undecided. Each verdict is compared with the
contest's consensus in ``--oracle`` (the files ``<model>-<RC|RF|UB|CTLC|CTLF|LTLC|LTLF>.out``
of the MCC 2021 ``oracle.tar.gz``, lines ``FORMULA <id> <TRUE|FALSE|integer> ...``):
right, wrong, or undecided (``null``). A formula the oracle has no verdict for is
counted apart (``no oracle``).

Printed: one line per model and category (right / wrong / undecided, CPU seconds,
whether the budget stopped it), the totals per model and overall. No peer is wired in:
the contest's tools (LoLA, TAPAAL, ITS-Tools) are not Python and not installed here.
The last column counts the formulas decided by stubborn sets (their ``method``);
``--reduction`` and ``--check-states`` choose ``check_properties``' reduction and state
budget (``--check-states`` below a model's size puts it over budget, where ``auto``
reduces and ``none`` does not).

``--sample N --seed S --inputs DIR --state-space DIR`` first picks the sample and
extracts it into ``--models``: from the contest's input archives ``DIR/<model>.tgz``,
the P/T models (``-PT-`` in the name) whose StateSpace oracle
(``--state-space``: ``<model>-SS.out``, ``STATE_SPACE STATES n``) says at most
``--max-states`` states, families in ``--exclude`` left out; then ``--pick family``
(the default): one per family (the family's smallest such instance), ``N`` families
drawn by ``random.Random(S).sample`` (families sorted by name first); ``--pick model``:
``N`` of all those models drawn the same way (sorted by name first), so larger
instances come in.

Usage::

    python bench/mcc.py --sample 12 --seed 2021 --inputs INPUTS --state-space SS \\
        --exclude CircularTrains,Dekker,Eratosthenes,GPPP,HouseConstruction,Philosophers,ResAllocation,RobotManipulation \\
        --models out/mcc-sample --oracle ORACLE
    python bench/mcc.py --models out/mcc-sample --oracle ORACLE [--json out.json]
    python bench/mcc.py --models DIR --oracle ORACLE --only LTLCardinality,LTLFireability
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import random
import resource
import sys
import tarfile
import time
from pathlib import Path
from typing import Any

CATEGORIES = {"ReachabilityCardinality": "RC", "ReachabilityFireability": "RF", "UpperBounds": "UB",
              "CTLCardinality": "CTLC", "CTLFireability": "CTLF", "LTLCardinality": "LTLC",
              "LTLFireability": "LTLF"}


def oracle_verdicts(oracle: Path, model: str, category: str) -> dict[str, str]:
    """``{formula id: "TRUE" | "FALSE" | "<integer>"}`` of the consensus file."""
    path = oracle / f"{model}-{CATEGORIES[category]}.out"
    found: dict[str, str] = {}
    if path.is_file():
        for line in path.read_text().splitlines():
            words = line.split()
            if len(words) >= 3 and words[0] == "FORMULA":
                found[words[1]] = words[2]
    return found


def _verdict_text(verdict: Any) -> str | None:
    if verdict is None:
        return None
    if isinstance(verdict, bool):
        return "TRUE" if verdict else "FALSE"
    return str(verdict)


def _category_child(model_dir: str, category: str, budget: float, pipe, reduction: str = "auto",
                    max_states: int | None = None) -> None:
    soft, hard = resource.getrlimit(resource.RLIMIT_CPU)
    limit = int(budget) + 1
    resource.setrlimit(resource.RLIMIT_CPU, (limit, hard if hard != resource.RLIM_INFINITY and hard < limit
                                              else resource.RLIM_INFINITY))
    from petriflow.io import load_net
    from petriflow.properties.check import check_properties
    from petriflow.properties.mcc_xml import load_mcc_properties

    start = time.process_time()
    net = load_net(Path(model_dir) / "model.pnml")
    properties = load_mcc_properties(Path(model_dir) / f"{category}.xml")
    results = check_properties(net, properties, reduction=reduction,
                               **({"max_states": max_states} if max_states else {}))
    pipe.send({"cpu_s": time.process_time() - start,
               "verdicts": {r["id"]: _verdict_text(r["verdict"]) for r in results},
               "methods": {r["id"]: r.get("method") or r.get("reason") for r in results}})


def run_category(model_dir: Path, category: str, budget: float, wall: float, reduction: str = "auto",
                 max_states: int | None = None) -> dict[str, Any]:
    """Decide one category of one model in a fresh process within ``budget`` CPU s
    (and ``wall`` seconds), with ``check_properties``' ``reduction`` and ``max_states``."""
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    child = context.Process(target=_category_child, args=(str(model_dir), category, budget, send,
                                                                      reduction, max_states))
    start = time.perf_counter()
    child.start()
    send.close()
    try:
        row = receive.recv() if receive.poll(wall) else {"stopped": "wall clock"}
    except EOFError:                         # killed by RLIMIT_CPU (SIGXCPU) or an error
        row = {"stopped": "budget"}
    child.kill()
    child.join()
    if child.exitcode not in (0, None) and "verdicts" not in row and row.get("stopped") != "wall clock":
        row["stopped"] = "budget" if child.exitcode in (-24, -9) else f"exit {child.exitcode}"
    row["wall_s"] = time.perf_counter() - start
    return row


def score(row: dict[str, Any], expected: dict[str, str]) -> dict[str, Any]:
    got = row.get("verdicts", {})
    counts = {"right": 0, "wrong": 0, "undecided": 0, "no_oracle": 0}
    wrong = []
    for formula, answer in expected.items():
        verdict = got.get(formula)
        if verdict is None:
            counts["undecided"] += 1
        elif verdict == answer:
            counts["right"] += 1
        else:
            counts["wrong"] += 1
            wrong.append((formula, verdict, answer))
    counts["no_oracle"] = sum(1 for f, v in got.items() if f not in expected and v is not None)
    return {**counts, "wrong_ids": wrong}


def pick_sample(inputs: Path, state_space: Path, n: int, seed: int, max_states: int,
                exclude: set[str], pick: str = "family") -> list[str]:
    """The sample rule (see the module documentation): ``family``: one smallest instance
    per family, ``N`` families drawn; ``model``: ``N`` models drawn among all that qualify."""
    best: dict[str, tuple[int, str]] = {}
    every: list[str] = []
    for archive in sorted(inputs.glob("*-PT-*.tgz")):
        model = archive.name[:-len(".tgz")]
        family = model.split("-PT-")[0]
        oracle = state_space / f"{model}-SS.out"
        if family in exclude or not oracle.is_file():
            continue
        states = None
        for line in oracle.read_text().splitlines():
            words = line.split()
            if words[:2] == ["STATE_SPACE", "STATES"] and len(words) > 2:
                try:
                    states = int(float(words[2]))
                except (ValueError, OverflowError):
                    states = None
        if states is None or states > max_states:
            continue
        every.append(model)
        if family not in best or (states, model) < best[family]:
            best[family] = (states, model)
    if pick == "model":
        return sorted(random.Random(seed).sample(every, min(n, len(every))))
    families = sorted(best)
    chosen = random.Random(seed).sample(families, min(n, len(families)))
    return sorted(best[f][1] for f in chosen)


def extract(inputs: Path, models: list[str], into: Path) -> None:
    into.mkdir(parents=True, exist_ok=True)
    for model in models:
        with tarfile.open(inputs / f"{model}.tgz") as archive:
            archive.extractall(into, filter="data")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--models", required=True, type=Path, help="folder of model folders")
    parser.add_argument("--oracle", required=True, type=Path, help="folder of <model>-<cat>.out files")
    parser.add_argument("--budget", type=float, default=60.0, help="CPU seconds per model and category")
    parser.add_argument("--wall", type=float, help="wall-clock seconds per category (default 10 x budget)")
    parser.add_argument("--only", help="comma-separated categories (default: all seven)")
    parser.add_argument("--json", metavar="OUT", help="also write the rows as JSON")
    parser.add_argument("--sample", type=int, help="pick and extract N models first (needs --inputs)")
    parser.add_argument("--seed", type=int, default=2021)
    parser.add_argument("--inputs", type=Path, help="the contest's <model>.tgz archives")
    parser.add_argument("--state-space", type=Path, help="the StateSpace oracle's <model>-SS.out files")
    parser.add_argument("--max-states", type=int, default=2_000_000)
    parser.add_argument("--pick", choices=("family", "model"), default="family",
                        help="draw N families (their smallest instance) or N models")
    parser.add_argument("--exclude", default="", help="comma-separated families left out of the sample")
    parser.add_argument("--reduction", choices=("auto", "stubborn", "none"), default="auto",
                        help="check_properties' reduction: stubborn sets where the graph is over"
                        " budget (auto), for every EF/AG and LTL without X (stubborn), never (none)")
    parser.add_argument("--check-states", type=int, metavar="N",
                        help="check_properties' max_states (default its own, 2,000,000)")
    args = parser.parse_args(argv)
    if args.sample:
        if args.inputs is None or args.state_space is None:
            parser.error("--sample needs --inputs and --state-space")
        chosen = pick_sample(args.inputs, args.state_space, args.sample, args.seed, args.max_states,
                             {f for f in args.exclude.split(",") if f}, args.pick)
        print("sample:", " ".join(chosen), flush=True)
        extract(args.inputs, chosen, args.models)
    categories = args.only.split(",") if args.only else list(CATEGORIES)
    rows = []
    total = {"right": 0, "wrong": 0, "undecided": 0, "no_oracle": 0}
    print(f"{'model':40} {'category':24} {'right':>5} {'wrong':>5} {'undec':>5} {'CPU s':>7} {'wall s':>7} {'stubborn':>7}")
    for model_dir in sorted(p for p in args.models.iterdir() if (p / "model.pnml").is_file()):
        per_model = {"right": 0, "wrong": 0, "undecided": 0, "no_oracle": 0}
        for category in categories:
            expected = oracle_verdicts(args.oracle, model_dir.name, category)
            row = run_category(model_dir, category, args.budget, args.wall or 10 * args.budget,
                               args.reduction, args.check_states)
            counts = score(row, expected)
            row.update(model=model_dir.name, category=category, **counts)
            rows.append(row)
            for key in per_model:
                per_model[key] += counts[key]
            stopped = f"  stopped: {row['stopped']}" if "stopped" in row else ""
            cpu = row.get("cpu_s")
            reduced = sum("stubborn sets" in (m or "") for m in row.get("methods", {}).values())
            print(f"{model_dir.name:40} {category:24} {counts['right']:5} {counts['wrong']:5}"
                  f" {counts['undecided']:5} {cpu if cpu is not None else float('nan'):7.2f}"
                  f" {row['wall_s']:7.2f} {reduced:7}{stopped}", flush=True)
            for formula, verdict, answer in counts["wrong_ids"]:
                print(f"  WRONG {formula}: {verdict}, the contest says {answer}", flush=True)
        for key in total:
            total[key] += per_model[key]
        print(f"{model_dir.name:40} {'(model)':24} {per_model['right']:5} {per_model['wrong']:5}"
              f" {per_model['undecided']:5}", flush=True)
    decided = total["right"] + total["wrong"]
    verdicts = decided + total["undecided"]
    print(f"\ntotal: {verdicts} verdicts, {total['right']} right, {total['wrong']} wrong,"
          f" {total['undecided']} undecided ({100 * decided / max(verdicts, 1):.1f} % decided)")
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2, default=str))
    return 1 if total["wrong"] else 0


if __name__ == "__main__":
    sys.exit(main())
