#!/usr/bin/env bash
# The test suite, as CI runs it (README's second command).
#
# The default run leaves out the tests marked `slow` (the benchmarks' end-to-end smoke
# tests and the longest experiments); CI (CI=true), or PETRIFLOW_SLOW_TESTS=1, runs them
# as a second step. Each step prints the names of failing tests in its last lines, and
# fails when it selects no test at all (pytest's exit code 5).
set -euo pipefail
cd "$(dirname "$0")/.."
.venv/bin/python -m pytest -q -rsfE "$@"
if [ "${CI:-}" = "true" ] || [ "${PETRIFLOW_SLOW_TESTS:-}" = "1" ]; then
    .venv/bin/python -m pytest -q -rsfE -m slow "$@"
fi
