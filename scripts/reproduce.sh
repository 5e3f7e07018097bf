#!/usr/bin/env bash
# Reproduce the five papers: run every sweep file with published values
# (nets/*/experiments/*.yaml with paper:) and write docs/reproduction.md: every published
# value beside the measured mean ± sd, its status (predicted, built in, missed) and the
# deviation, with the counts of each status. Each table's results database and page
# (petriflow view) are kept under out/reproduction/SCENARIO/ (generated, not in git);
# running it again resumes what the same code already measured.
#
#   scripts/reproduce.sh                 # every table with its own trials
#   scripts/reproduce.sh --quick         # one trial a row: out/reproduction-quick/reproduction.md
#   scripts/reproduce.sh --only comm,slam --workers 2
# Other options are petriflow reproduce's (petriflow reproduce --help).
set -euo pipefail
cd "$(dirname "$0")/.."
commit="$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
if ! git diff --quiet HEAD -- petriflow agents nets 2>/dev/null; then
    commit="$commit+changes"
fi
exec .venv/bin/petriflow reproduce nets --commit "$commit" "$@"
