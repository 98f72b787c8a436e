#!/usr/bin/env bash
# Environment lighting in the reference (docs/LIGHTING.md): run time and
# seed-to-seed noise of `sunbeam-eval render` against samples per pixel, a
# sky-lit sphere and the demo snake. Needs the demo's outputs (make demo, or
# OUT=DIR for another demo output folder). Prints a markdown table.
#   docs/bench/lighting.sh [OUT]
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=${1:-examples/out}
EVAL=target/release/sunbeam-eval
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
pack=$(realpath "$OUT/xeno.ktx2")
snake=$(realpath "$OUT/snake.glb")
cat > "$T/sphere.json" <<JSON
{ "camera": { "eye": [0, 0.6, 2.6], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "$pack", "base_color": [0.03, 0.03, 0.035], "diffuse_weight": 0.15 } ],
  "environment": { "sky": { "sun_elevation_deg": 25, "sun_azimuth_deg": 120, "turbidity": 3 }, "intensity": 1 },
  "exposure": -1.5, "size": [64, 64] }
JSON
sed -e "s|@PACK@|$pack|" -e "s|@MESH@|$snake|" examples/sky-scene.json.in > "$T/snake.json"
echo "| scene | size | samples | seconds | seed 1 vs 2: CIEDE2000 mean / p99 / max |"
echo "|---|---|---|---|---|"
for scene in sphere snake; do
  size=64x64; [ $scene = snake ] && size=192x108
  for s in 16 64 256; do
    t0=$(date +%s.%N)
    $EVAL render "$T/$scene.json" --size $size --samples $s --seed 1 -o "$T/a.exr"
    t1=$(date +%s.%N)
    d=$($EVAL render "$T/$scene.json" --size $size --samples $s --seed 2 -o "$T/b.exr" --compare "$T/a.exr")
    echo "| $scene | $size | $s | $(echo "$t1 - $t0" | bc) | $(echo "$d" | sed -E 's/CIEDE2000 mean ([0-9.]+) p99 ([0-9.]+) max ([0-9.]+) over ([0-9]+) px/\1 \/ \2 \/ \3 (\4 px)/') |"
  done
done
