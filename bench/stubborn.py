"""Stubborn sets for properties against the same search without them: markings and CPU s.

For each model folder (``model.pnml`` and the contest's property files) and each of
ReachabilityCardinality, ReachabilityFireability, LTLCardinality, LTLFireability, every
formula the reduction applies to (``EF p``/``AG p``; LTL without ``X``) is decided twice
from the net, no reachability graph built, with at most ``--max-states`` markings per
formula: by :func:`petriflow.properties.partial_order.reach_stubborn` /
:func:`petriflow.properties.ltl.check_ltl_on_net` with the reduction, and by the same
search exploring every enabled row. Printed per model and category: formulas, decided
(full / reduced), markings stored (summed; an undecided formula counts its budget),
CPU seconds, and whether the two verdicts ever differ (they must not), and, with
``--oracle`` (the contest's ``<model>-<RC|RF|LTLC|LTLF>.out`` files), wrong verdicts.

Usage::

    python bench/stubborn.py MODEL_DIR... [--max-states 50000] [--oracle DIR] [--json OUT]
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from petriflow.analysis.exploration import StateSpaceLimit
from petriflow.io import load_net
from petriflow.properties.language import Not
from petriflow.properties.ltl import check_ltl_on_net
from petriflow.properties.mcc_xml import load_mcc_properties
from petriflow.properties.partial_order import PropertyStubbornSets, has_next, reach_stubborn

CATEGORIES = {"ReachabilityCardinality": "RC", "ReachabilityFireability": "RF",
              "LTLCardinality": "LTLC", "LTLFireability": "LTLF"}


def _oracle(folder: Path | None, model: str, category: str) -> dict[str, str]:
    if folder is None:
        return {}
    path = folder / f"{model}-{CATEGORIES[category]}.out"
    if not path.is_file():
        return {}
    found = {}
    for line in path.read_text().splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[0] == "FORMULA":
            found[parts[1]] = parts[2]
    return found


def _decide(net, prop, reduced: bool, max_states: int) -> tuple[bool | None, int]:
    """``(verdict or None, markings stored)`` of one formula, one way."""
    formula = prop.formula
    if prop.kind == "ltl":
        stats: dict = {}
        try:
            verdict, _ = check_ltl_on_net(net, net.initial_marking, formula, max_states=max_states,
                                          stubborn=reduced, stats=stats)
        except StateSpaceLimit:
            return None, max_states
        return verdict, stats["markings"]
    universal = type(formula).__name__ == "AllPaths"
    predicate = formula.operand.operand
    sets = PropertyStubbornSets(net)
    sets.reduced = sets.reduced and reduced
    try:
        found = reach_stubborn(net, net.initial_marking, Not(predicate) if universal else predicate,
                               max_states=max_states, sets=sets)
    except StateSpaceLimit:
        return None, max_states
    return found.found != universal, found.states


def _applies(prop) -> bool:
    if prop.kind == "ltl":
        return not has_next(prop.formula)
    return prop.kind == "reachability" and type(prop.formula).__name__ in ("AllPaths", "ExistsPath")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="+", type=Path)
    parser.add_argument("--max-states", type=int, default=50_000)
    parser.add_argument("--oracle", type=Path)
    parser.add_argument("--json", metavar="OUT")
    args = parser.parse_args(argv)
    rows = []
    print("| model | category | formulas | decided full / reduced | markings full / reduced |"
          " CPU s full / reduced | verdicts differ | wrong |")
    print("|---|---|---:|---|---|---|---|---:|")
    for folder in args.models:
        net = load_net(folder / "model.pnml")
        for category in CATEGORIES:
            expected = _oracle(args.oracle, folder.name, category)
            props = [p for p in load_mcc_properties(folder / f"{category}.xml") if _applies(p)]
            row = {"model": folder.name, "category": category, "formulas": len(props),
                   "decided": [0, 0], "markings": [0, 0], "cpu": [0.0, 0.0], "differ": 0, "wrong": 0}
            for prop in props:
                verdicts = []
                for k, reduced in enumerate((False, True)):
                    began = time.process_time()
                    verdict, markings = _decide(net, prop, reduced, args.max_states)
                    row["cpu"][k] += time.process_time() - began
                    row["markings"][k] += markings
                    row["decided"][k] += verdict is not None
                    verdicts.append(verdict)
                    if verdict is not None and prop.id in expected and \
                            ("TRUE" if verdict else "FALSE") != expected[prop.id]:
                        row["wrong"] += 1
                if None not in verdicts and verdicts[0] != verdicts[1]:
                    row["differ"] += 1
            rows.append(row)
            print(f"| {folder.name} | {category} | {row['formulas']} | {row['decided'][0]} / {row['decided'][1]}"
                  f" | {row['markings'][0]:,} / {row['markings'][1]:,} | {row['cpu'][0]:.1f} / {row['cpu'][1]:.1f}"
                  f" | {row['differ']} | {row['wrong']} |", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=1))
    return 1 if any(r["differ"] or r["wrong"] for r in rows) else 0


if __name__ == "__main__":
    sys.exit(main())
