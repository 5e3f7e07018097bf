#!/usr/bin/env bash
# Install everything petriflow needs on a fresh Debian/Ubuntu machine with Python >= 3.10,
# into a virtual environment of the project's own (.venv), so the distribution's Python
# stays untouched (PEP 668: "externally managed"). What the distribution must provide
# (Graphviz for net pictures, the venv module) comes from apt-get when it is missing.
# Run it again at any time: it only installs what is missing or changed.
set -euo pipefail
cd "$(dirname "$0")/.."

PYTHON=${PYTHON:-python3}
if ! "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 10))' 2>/dev/null; then
    echo "setup: petriflow needs Python >= 3.10 as $PYTHON (set PYTHON=... to use another)" >&2
    exit 2
fi

packages=()
command -v dot >/dev/null 2>&1 || packages+=(graphviz)
# a headless browser for the tests of petriflow view's pages (Selenium drives it)
command -v chromium >/dev/null 2>&1 || packages+=(chromium)
command -v chromedriver >/dev/null 2>&1 || packages+=(chromium-driver)
# Node.js runs the page's pure replay script in the tests (tests/view/test_replay_js.py)
command -v node >/dev/null 2>&1 || packages+=(nodejs)
# the MQTT broker the bridge's tests start on loopback (docs/bridge.md); Zenoh needs none
command -v mosquitto >/dev/null 2>&1 || [ -x /usr/sbin/mosquitto ] || packages+=(mosquitto)
if [ ! -x .venv/bin/python ] && ! "$PYTHON" -c 'import ensurepip, venv' >/dev/null 2>&1; then
    packages+=("python3-venv")
fi
if [ ${#packages[@]} -gt 0 ]; then
    SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
    echo "setup: installing ${packages[*]} with apt-get" >&2
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${packages[@]}" >/dev/null
fi

if [ ! -x .venv/bin/python ]; then
    "$PYTHON" -m venv .venv
fi
.venv/bin/python -m pip install -q --disable-pip-version-check --upgrade pip
# setuptools boxes a generic warning around every editable install whose packages map
# folders (agents/ -> petriflow.agents): it says nothing about this project, so it is
# silenced by its message; every other warning still shows.
PYTHONWARNINGS="ignore:Editable installation" \
    .venv/bin/python -m pip install -q --disable-pip-version-check -e ".[dev]"
echo "setup: done; run 'source .venv/bin/activate' to have the petriflow command on your PATH" >&2
