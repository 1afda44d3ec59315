#!/usr/bin/env bash
# Create .venv and install gcodekit with its test tools, once per change of
# pyproject.toml.  Sourced by run-examples.sh and run-tests.sh.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VENV="$ROOT/.venv"
STAMP="$VENV/.gcodekit-installed"
PY=${PYTHON:-python3}

die() { echo "gcodekit setup: $*" >&2; exit 1; }

command -v "$PY" >/dev/null || die "$PY not found; install Python 3.11 or newer (apt-get install python3)"
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' || die "Python 3.11 or newer is needed, found $("$PY" -V)"

if [ ! -x "$VENV/bin/python" ]; then
  if ! "$PY" -m venv "$VENV" 2>/dev/null; then
    rm -rf "$VENV"
    if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
      echo "gcodekit setup: installing python3-venv with apt-get" >&2
      { apt-get update -qq && apt-get install -y -qq python3-venv >/dev/null; } || die "apt-get could not install python3-venv"
      "$PY" -m venv "$VENV" || die "cannot create a virtual environment in $VENV"
    else
      die "cannot create a virtual environment; install the python3-venv package"
    fi
  fi
fi

want=$(cat "$ROOT/pyproject.toml" | sha256sum | cut -d' ' -f1)
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$want" ]; then
  echo "gcodekit setup: installing gcodekit and its test tools into .venv" >&2
  "$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1 || true
  "$VENV/bin/python" -m pip install -q -e "$ROOT[test]" || die "pip could not install gcodekit (is the package index reachable?)"
  echo "$want" > "$STAMP"
fi
