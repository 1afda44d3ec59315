#!/usr/bin/env bash
# The main job: report every bundled example (HTML and PDF per program, and
# out/reports/index.html), and write its summary (text and JSON) and motion
# table into out/examples/.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
source "$ROOT/scripts/setup.sh"
OUT="$ROOT/out/examples"
mkdir -p "$OUT"
for program in "$ROOT"/examples/*.*; do
  name=$(basename "$program")
  "$VENV/bin/gcodekit" info "$program" | tee "$OUT/$name.txt"
  "$VENV/bin/gcodekit" info "$program" --json > "$OUT/$name.json"
  "$VENV/bin/gcodekit" export "$program" --to csv -o "$OUT/$name.motions.csv" --force
done
"$VENV/bin/gcodekit" report "$ROOT"/examples/*.* -o "$ROOT/out/reports" --workers 2 --force
echo "summaries and motion tables written to $OUT"
echo "reports written to $ROOT/out/reports (open index.html)"
