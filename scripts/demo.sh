#!/usr/bin/env bash
# The main example: describe, check the format of, play and draw the inspection workflow.
set -euo pipefail
cd "$(dirname "$0")/.."
net=nets/examples/inspection.yaml
mkdir -p out
petriflow info "$net"
echo
petriflow simulate "$net" --steps 50 --seed 1
echo
petriflow fire "$net" capture segment dispatch
petriflow export "$net" -f pnml -o out/inspection.pnml
petriflow export "$net" -f svg -o out/inspection.svg
petriflow export "$net" -f png -o out/inspection.png
petriflow export out/inspection.pnml -f yaml -o out/inspection.roundtrip.yaml
echo
echo "wrote out/inspection.{pnml,svg,png} and out/inspection.roundtrip.yaml"
