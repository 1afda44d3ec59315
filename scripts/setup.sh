#!/usr/bin/env bash
# Create .venv and install gcodekit with its test and report tools, once per
# change of pyproject.toml; install Chromium (PDF reports) and poppler-utils
# (the PDF test) with apt-get when missing, and for the tests LinuxCNC's rs274
# (the differential check against it) and Cura's printer definitions.  Sourced by run-examples.sh and
# run-tests.sh (which sets GCODEKIT_SETUP_RS274=1).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
VENV="$ROOT/.venv"
STAMP="$VENV/.gcodekit-installed"
PY=${PYTHON:-python3}

die() { echo "gcodekit setup: $*" >&2; exit 1; }

source "$ROOT/scripts/apt.sh"

command -v "$PY" >/dev/null || die "$PY not found; install Python 3.11 or newer (apt-get install python3)"
"$PY" -c 'import sys; sys.exit(sys.version_info < (3, 11))' || die "Python 3.11 or newer is needed, found $("$PY" -V)"

if [ ! -x "$VENV/bin/python" ]; then
  if ! "$PY" -m venv "$VENV" 2>/dev/null; then
    rm -rf "$VENV"
    if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
      apt_install "virtual environments" python3-venv
      "$PY" -m venv "$VENV" || die "cannot create a virtual environment in $VENV"
    else
      die "cannot create a virtual environment; install the python3-venv package"
    fi
  fi
fi

# Debian packages: Mesa's EGL and software renderer draw the off-screen 3D
# pictures (VTK through EGL), chromium prints the PDF reports and pdftoppm
# (poppler-utils) checks them in the tests.
missing=()
compgen -G '/usr/lib/*/libEGL.so.1' >/dev/null && [ -e /usr/share/glvnd/egl_vendor.d/50_mesa.json ] \
  || missing+=(libegl1 libegl-mesa0 libgl1-mesa-dri)
command -v chromium >/dev/null || command -v chromium-browser >/dev/null || command -v google-chrome >/dev/null \
  || missing+=(chromium)
command -v pdftoppm >/dev/null || missing+=(poppler-utils)
if [ ${#missing[@]} -gt 0 ]; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt_install "pictures and PDF reports" "${missing[@]}"
  else
    die "pictures and PDF reports need ${missing[*]}: install them (apt-get install ${missing[*]}) as root, then run this again"
  fi
fi

# LinuxCNC's standalone interpreter rs274 (Debian package linuxcnc-uspace) is the reference the
# differential tests run against; without it they skip, so only the test command asks for it.
if [ "${GCODEKIT_SETUP_RS274:-0}" = 1 ] && [ ! -x /usr/bin/rs274 ]; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt_install "LinuxCNC's rs274, the reference of the differential tests" --no-install-recommends linuxcnc-uspace
  else
    die "the differential tests need LinuxCNC's rs274: install it as root (apt-get install --no-install-recommends linuxcnc-uspace), then run this again"
  fi
fi

# Cura's printer definitions (Debian package cura) are the reference the Creality Ender-3 preset is
# checked against (tests/test_slicer_figures.py); only the test command asks for them.
if [ "${GCODEKIT_SETUP_RS274:-0}" = 1 ] && [ ! -f /usr/share/cura/resources/definitions/creality_base.def.json ]; then
  if command -v apt-get >/dev/null && [ "$(id -u)" = 0 ]; then
    apt_install "Cura's printer definitions, the reference of the Ender-3 preset" --no-install-recommends cura
  else
    die "the slicer tests need Cura's printer definitions: install them as root (apt-get install --no-install-recommends cura), then run this again"
  fi
fi

want=$(cat "$ROOT/pyproject.toml" | sha256sum | cut -d' ' -f1)
if [ ! -f "$STAMP" ] || [ "$(cat "$STAMP")" != "$want" ]; then
  echo "gcodekit setup: installing gcodekit and its test tools into .venv" >&2
  "$VENV/bin/python" -m pip install -q --upgrade pip >/dev/null 2>&1 || true
  "$VENV/bin/python" -m pip install -q -e "$ROOT[test]" || die "pip could not install gcodekit (is the package index reachable?)"
  echo "$want" > "$STAMP"
fi

# An editable install leaves out data files: put gcodekit's Jupyter settings where its wheel puts them, so
# plain `jupyter nbconvert --to html` and JupyterLab's HTML export show the widgets' pictures offline here too.
mkdir -p "$VENV/etc/jupyter/jupyter_server_config.d"
cp "$ROOT/jupyter-config/jupyter_nbconvert_config.json" "$VENV/etc/jupyter/"
cp "$ROOT/jupyter-config/jupyter_server_config.d/gcodekit.json" "$VENV/etc/jupyter/jupyter_server_config.d/"
