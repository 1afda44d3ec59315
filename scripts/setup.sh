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

# Off-screen pictures (VTK through EGL) need Mesa's EGL and software renderer.
if ! { compgen -G '/usr/lib/*/libEGL.so.1' >/dev/null && [ -e /usr/share/glvnd/egl_vendor.d/50_mesa.json ]; }; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    echo "gcodekit setup: installing Mesa EGL (libegl1 libegl-mesa0 libgl1-mesa-dri) for off-screen pictures" >&2
    { apt-get update -qq && apt-get install -y -qq libegl1 libegl-mesa0 libgl1-mesa-dri >/dev/null; } \
      || echo "gcodekit setup: warning: apt-get could not install Mesa EGL; 3D pictures will fail" >&2
  else
    echo "gcodekit setup: warning: 3D pictures need Mesa EGL (apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri)" >&2
  fi
fi

want=$(cat "$ROOT/pyproject.toml" | sha256sum | cut -d' ' -f1)
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$want" ]; then
  echo "gcodekit setup: installing gcodekit and its test tools into .venv" >&2
  "$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1 || true
  "$VENV/bin/python" -m pip install -q -e "$ROOT[test]" || die "pip could not install gcodekit (is the package index reachable?)"
  echo "$want" > "$STAMP"
fi
