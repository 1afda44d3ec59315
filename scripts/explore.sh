#!/usr/bin/env bash
# Exploration, not a gate: the property tests with fresh random examples
# (hypothesis' "explore" profile) and the fuzz suite on a fresh seed.
#   ./scripts/explore.sh               # property tests, then 2000 fuzz cases
#   ./scripts/explore.sh --count 500   # other fuzz options: see python -m fuzz --help
# A failing example it finds is added to its test as an explicit @example
# (property tests) or a regression test (fuzz cases are saved in fuzz-failures/).
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$ROOT/scripts/setup.sh"
cd "$ROOT"
set +e  # run both parts, then report
mapfile -t property_tests < <(grep -l "from hypothesis import" tests/test_*.py)
"$VENV/bin/python" -m pytest "${property_tests[@]}" --hypothesis-profile=explore --hypothesis-show-statistics -q
tests_status=$?
PYTHONPATH="$ROOT/tests" "$VENV/bin/python" -m fuzz --keep "$ROOT/fuzz-failures" "$@"
fuzz_status=$?
exit $(( tests_status || fuzz_status ))
