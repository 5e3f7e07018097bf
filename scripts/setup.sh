#!/usr/bin/env bash
# Install everything petriflow needs on a fresh Debian/Ubuntu machine with Python >= 3.10:
# Graphviz (for net pictures) from the distribution, then petriflow with its test extras.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v dot >/dev/null 2>&1; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq graphviz >/dev/null
fi
python3 -m pip install -q --disable-pip-version-check -e ".[dev]"
