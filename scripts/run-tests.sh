#!/usr/bin/env bash
# The test suite: unit, golden and property tests plus the doctests.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
GCODEKIT_SETUP_RS274=1 source "$ROOT/scripts/setup.sh"
cd "$ROOT"
exec "$VENV/bin/python" -m pytest tests gcodekit --doctest-modules "$@"
