#!/usr/bin/env bash
# The Blender add-on's tests (tests/blender/test_addon.py), run by the Python of the cached bpy
# venv that scripts/ensure-bpy.sh installs (Blender as a module has no other interpreter).
# Without that venv: skip with a message, or fail under SUNBEAM_REQUIRE_ALL=1 (CI).
# SUNBEAM_BIN names the tools' folder (the Makefile passes its BIN).
set -euo pipefail
cd "$(dirname "$0")/../.."
VENV=${SUNBEAM_BPY_VENV:-${XDG_CACHE_HOME:-$HOME/.cache}/sunbeam/bpy-venv}
if [ ! -x "$VENV/bin/python" ]; then
  msg="tests/blender: no bpy venv at $VENV (scripts/ensure-bpy.sh installs it)"
  if [ "${SUNBEAM_REQUIRE_ALL:-}" = 1 ]; then echo "$msg" >&2; exit 1; fi
  echo "$msg: skipped" >&2
  exit 0
fi
exec "$VENV/bin/python" tests/blender/test_addon.py "$@"
