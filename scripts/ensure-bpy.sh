#!/usr/bin/env bash
# Install Blender as a Python module (bpy, pinned) into a cached virtual environment outside
# the clone, for the Blender add-on's tests (tests/blender). Idempotent: a venv that already
# imports the pinned bpy is left alone, so the common case costs one `python -c`.
# Prints nothing when all is there. Override the place with SUNBEAM_BPY_VENV; a wheel already
# downloaded can be given with SUNBEAM_BPY_WHEEL (or is found in pip's cache).
set -euo pipefail

BPY_VERSION=4.2.0
PYTHON=${SUNBEAM_BPY_PYTHON:-python3.11}
VENV=${SUNBEAM_BPY_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/sunbeam/bpy-venv}

if [ -x "$VENV/bin/python" ] && "$VENV/bin/python" -c "import importlib.metadata as m, sys; sys.exit(m.version('bpy') != '$BPY_VERSION')" 2>/dev/null; then
  exit 0
fi
command -v "$PYTHON" >/dev/null || { echo "ensure-bpy: $PYTHON not found (bpy $BPY_VERSION needs CPython 3.11)" >&2; exit 1; }
echo "ensure-bpy: installing bpy $BPY_VERSION into $VENV (one time, ~520 MB download)" >&2
# A half-made venv (an interrupted install) fails the check above and is rebuilt from scratch.
rm -rf "$VENV"
"$PYTHON" -m venv "$VENV"
src="bpy==$BPY_VERSION"
[ -n "${SUNBEAM_BPY_WHEEL:-}" ] && src="$SUNBEAM_BPY_WHEEL"
for i in 1 2 3; do
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check "$src" && break
  [ "$i" = 3 ] && { echo "ensure-bpy: pip install $src failed" >&2; exit 1; }
  sleep 5
done
