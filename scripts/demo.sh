#!/usr/bin/env bash
# The main scenario: the SMART helping task (nets/smart, seed 003) checked, run over
# pybullet with trace, XES log and journal, and drawn; then the small passage example.
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$PWD/.venv/bin:$PATH"   # the project's environment (scripts/setup.sh makes it)
mkdir -p out
rm -f out/smart.sqlite* out/passage.sqlite*

net=nets/smart/smart.yaml
petriflow info "$net"
echo
petriflow check "$net"
echo
petriflow run "$net" --trace out/smart.jsonl --xes out/smart.xes --db out/smart.sqlite
petriflow replay out/smart.jsonl > out/smart.replay.txt
grep -vE " T[1234] " out/smart.replay.txt | grep -E "fire|stop"   # the task, without the camera loop
petriflow export "$net" -f png -o out/smart.png
echo

net=nets/passage/passage.yaml
petriflow run "$net" --trace out/passage.jsonl --xes out/passage.xes --db out/passage.sqlite
petriflow export "$net" -f svg -o out/passage.svg
petriflow export "$net" -f pnml -o out/passage.pnml
petriflow export out/passage.pnml -f yaml -o out/passage.roundtrip.yaml
echo
echo "wrote out/smart.{jsonl,xes,sqlite,png,replay.txt} and out/passage.{jsonl,xes,sqlite,svg,pnml}, out/passage.roundtrip.yaml"
