#!/usr/bin/env bash
# The main scenario: two robots take turns through a narrow passage (nets/passage),
# run over pybullet with trace, XES log and journal; then the net is drawn and converted.
set -euo pipefail
cd "$(dirname "$0")/.."
net=nets/passage/passage.yaml
mkdir -p out
rm -f out/passage.sqlite out/passage.sqlite-wal out/passage.sqlite-shm
petriflow info "$net"
echo
petriflow run "$net" --trace out/passage.jsonl --xes out/passage.xes --db out/passage.sqlite
echo
petriflow replay out/passage.jsonl
petriflow export "$net" -f svg -o out/passage.svg
petriflow export "$net" -f png -o out/passage.png
petriflow export "$net" -f pnml -o out/passage.pnml
petriflow export out/passage.pnml -f yaml -o out/passage.roundtrip.yaml
echo
echo "wrote out/passage.{jsonl,xes,sqlite,svg,png,pnml} and out/passage.roundtrip.yaml"
