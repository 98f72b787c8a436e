#!/usr/bin/env bash
# Screenshots of the Blender add-on's panels (and of the 3D Viewport's rendered mode with the
# Sunbeam engine, which the script checks) for docs/BLENDER.md (`make blender-panels-img`):
# tests/blender/panel_screenshots.py in Blender's own executable with a window on a virtual
# display (xvfb-run). `make test` runs it through tests/blender/panels_test.sh.
#   tests/blender/panel_screenshots.sh [OUT_DIR]     (default docs/img)
# SUNBEAM_BLENDER names the executable (default: blender on PATH; Debian 12: `apt-get install
# blender`, 3.4.1). Fails with a message when Blender or xvfb-run is missing.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-docs/img}
BLENDER=${SUNBEAM_BLENDER:-blender}
if ! command -v "$BLENDER" >/dev/null; then
  echo "panel_screenshots: no Blender executable '$BLENDER' (install one, e.g. 'apt-get install blender', or set SUNBEAM_BLENDER=/path/to/blender)" >&2
  exit 1
fi
if ! command -v xvfb-run >/dev/null; then
  echo "panel_screenshots: no xvfb-run (apt-get install xvfb): Blender needs a display for screenshots" >&2
  exit 1
fi
# The virtual screen is the window's size: 520 px is the Properties editor's width once the
# script maximises it, 1250 px tall so that the Object tab fits. --enable-event-simulate lets the
# script move the pointer (and makes Blender ignore real input); --python-exit-code makes an
# exception in the script exit Blender with an error instead of leaving its window open.
status=0
timeout 300 xvfb-run -a -s "-screen 0 520x1250x24" "$BLENDER" --factory-startup \
  --enable-event-simulate --python-exit-code 1 \
  --python tests/blender/panel_screenshots.py -- "$OUT" || status=$?
if [ "$status" != 0 ]; then
  echo "panel_screenshots: Blender failed (exit status $status)" >&2
  exit "$status"
fi
