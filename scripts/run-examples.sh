#!/usr/bin/env bash
# The main job: report every bundled example (HTML and PDF per program, and
# out/reports/index.html), and write its summary (text and JSON), motion table
# and picture into out/examples/, and for additive programs a VTK mesh and an
# Abaqus event series.
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
  "$VENV/bin/gcodekit" render "$program" -o "$OUT/$name.png" --force
  # additive programs (those with layers) also as a VTK mesh and an Abaqus event series
  if "$VENV/bin/python" -c 'import json, sys; sys.exit(json.load(open(sys.argv[1]))["layers"] is None)' "$OUT/$name.json"; then
    "$VENV/bin/gcodekit" export "$program" --to vtk -o "$OUT/$name.vtp" --force
    "$VENV/bin/gcodekit" export "$program" --to events -o "$OUT/$name.events.csv" --force
  fi
done
"$VENV/bin/gcodekit" report "$ROOT"/examples/*.* -o "$ROOT/out/reports" --workers 2 --force
echo "summaries, motion tables, pictures, VTK meshes and event series written to $OUT"
echo "reports written to $ROOT/out/reports (open index.html)"
