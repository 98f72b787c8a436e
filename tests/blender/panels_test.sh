#!/usr/bin/env bash
# `make test`'s check of the add-on's panels in Blender's own executable: takes the screenshots of
# tests/blender/panel_screenshots.sh into target/tmp/blender-panels (so the panels register and
# draw in a real Blender with a window, every step of the script succeeding) and compares each
# with docs/img/blender-panel-*.png (idiff: the same size, at most 0.02 % of the pixels off by
# more than 0.2: a label's changed word moves hundreds; two runs here write the same bytes), so
# that docs/BLENDER.md shows what the add-on draws now.
# Without Blender's executable: skip with a message, or fail under SUNBEAM_REQUIRE_ALL=1 (CI;
# scripts/ensure-deps.sh installs Debian's `blender`).
set -euo pipefail
cd "$(dirname "$0")/../.."
BLENDER=${SUNBEAM_BLENDER:-blender}
if ! command -v "$BLENDER" >/dev/null || ! command -v idiff >/dev/null; then
  msg="tests/blender/panels_test.sh: no Blender executable '$BLENDER' or no idiff (apt-get install blender openimageio-tools)"
  if [ "${SUNBEAM_REQUIRE_ALL:-}" = 1 ]; then echo "$msg" >&2; exit 1; fi
  echo "$msg: skipped" >&2
  exit 0
fi
OUT=target/tmp/blender-panels
rm -rf "$OUT"
mkdir -p "$OUT"
tests/blender/panel_screenshots.sh "$OUT"
status=0
n=0
for doc in docs/img/blender-panel-*.png; do
  # Never compared: the viewport's rendered mode (sunbeam-play's frame may depend on timing);
  # panel_screenshots.py checks that picture itself and fails the run above when it is wrong.
  case "$(basename "$doc")" in blender-viewport-*) continue ;; esac
  n=$((n + 1))
  new="$OUT/$(basename "$doc")"
  if [ ! -f "$new" ]; then
    echo "panels_test: $new was not written" >&2
    status=1
  elif ! idiff -q -fail 0.2 -failpercent 0.02 -warn 0.2 -warnpercent 0.02 "$doc" "$new" >/dev/null; then
    echo "panels_test: $doc differs from what the add-on draws now ($new): run 'make blender-panels-img'" >&2
    idiff -fail 0.2 -failpercent 0.02 "$doc" "$new" >&2 || true
    status=1
  fi
done
if [ "$n" -lt 4 ] || [ "$(ls "$OUT"/blender-panel-*.png | wc -l)" != "$n" ]; then
  echo "panels_test: expected the same 4 or more panels in docs/img and $OUT" >&2
  status=1
fi
if [ ! -f "$OUT/blender-viewport-rendered.png" ]; then
  echo "panels_test: $OUT/blender-viewport-rendered.png was not written" >&2
  status=1
fi
[ "$status" = 0 ] && echo "panels_test: $n panel screenshots match docs/img" >&2
exit "$status"
