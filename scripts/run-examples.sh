#!/usr/bin/env bash
# The main job: emulate every bundled example and write its summary (text and
# JSON) and motion table into out/examples/.
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
echo "summaries and motion tables written to $OUT"
