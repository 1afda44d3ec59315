#!/usr/bin/env bash
# The test suite: unit, golden and property tests plus the doctests (./scripts/run-tests.sh [PYTEST ARGS]).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GCODEKIT_SETUP_RS274=1 source "$ROOT/scripts/setup.sh"
cd "$ROOT"
# Arguments naming tests (files, folders, node ids) run just those; other arguments (-k, -x, ...) go with
# the whole suite.
targets=(tests gcodekit)
for arg in "$@"; do
  [ -e "${arg%%::*}" ] && { targets=(); break; }
done
exec "$VENV/bin/python" -m pytest "${targets[@]}" --doctest-modules "$@"
