#!/usr/bin/env bash
# The player's frame cost on a real GPU at 1920 x 1080 (issue 26's figure;
# docs/bench/play.md "Real GPU"), as one short run for a lent device machine,
# whose time is counted: every scene's cells first frame and its Lambert
# frame in the same process (`--bench --json`, the median of FRAMES), the
# point light and Monte Carlo beside them, and one headless first frame of
# the sphere written as EXR to compare with lavapipe's at home.
#
#   tools/sunbeam-play/bench/gpu.sh DATA_DIR OUT_DIR
#
# DATA_DIR holds what the run needs, made at home (the device builds
# nothing and reaches nothing):
#   sunbeam-play        a stripped release binary (`strip -o DATA/sunbeam-play
#                       target/release/sunbeam-play`, about 16 MB)
#   x5.ktx2, x5.response.ktx2
#                       the 5 um synthetic Xenopeltis pack (`sunbeam-import
#                       synthetic:xenopeltis --synthetic-size 256
#                       --synthetic-pixel 20nm -o x5.exr`, `sunbeam-pack x5.exr
#                       -o x5.ktx2 --response`); its environment maps are built
#                       on the device at start (they are 110 MB)
#   snake.glb           `sunbeam-bake --generate-snake --pack x5.ktx2`
#   studio.exr          ../shared/data/hdri/studio.exr (optional)
# SIZE (default 1920x1080) and FRAMES (default 5) change the run; at home
# `SIZE=64x36 FRAMES=2 gpu.sh DATA OUT` checks the script on lavapipe.
# OUT_DIR gets gpu.jsonl (one `--bench --json` report a line, with "scene"
# and "what" added), gpu.md (a table: frame ms, Lambert ms, ratio) and
# sphere-first.exr.
set -euo pipefail
data=$(realpath "${1:?usage: gpu.sh DATA_DIR OUT_DIR}")
out=${2:?usage: gpu.sh DATA_DIR OUT_DIR}
mkdir -p "$out"
out=$(realpath "$out")
size=${SIZE:-1920x1080}
frames=${FRAMES:-5}
play="$data/sunbeam-play"
for f in sunbeam-play x5.ktx2 x5.response.ktx2 snake.glb; do
  [ -e "$data/$f" ] || { echo "gpu.sh: $data/$f missing (see the script's header)" >&2; exit 1; }
done
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
w=${size%x*}
h=${size#*x}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The scenes: the sky-lit sphere of docs/BENCHMARKS.md filling the frame,
# the same under studio.exr, and the snake's default scene (the sky, shown
# behind).
sphere() {
  cat <<EOF
{ "camera": { "eye": [0, 0.25, 1.2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "$data/x5.ktx2", "base_color": [0.0012, 0.0012, 0.0014], "diffuse_weight": 0.15, "masking": "smith" } ],
  "environment": $1, "exposure": 3.1, "size": [$w, $h] }
EOF
}
sphere '{ "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 70, "turbidity": 3 }, "intensity": 1 }' > "$work/sphere-sky.json"
scenes=(sphere-sky)
if [ -e "$data/studio.exr" ]; then
  sphere "{ \"map\": \"$data/studio.exr\", \"rotation_deg\": 30 }" > "$work/sphere-studio.json"
  scenes+=(sphere-studio)
fi
: > "$out/gpu.jsonl"
bench() {
  local scene=$1 what=$2
  shift 2
  local t0 t1 report
  t0=$(date +%s.%N)
  report=$("$play" "$@" --bench --json --frames "$frames" 2> "$work/err.txt") || {
    echo "gpu.sh: $scene $what failed:" >&2
    cat "$work/err.txt" >&2
    return 1
  }
  t1=$(date +%s.%N)
  python3 -c 'import json,sys; r=json.loads(sys.argv[1]); r["scene"]=sys.argv[2]; r["what"]=sys.argv[3]; r["process_s"]=round(float(sys.argv[5])-float(sys.argv[4]),3); print(json.dumps(r))' \
    "$report" "$scene" "$what" "$t0" "$t1" >> "$out/gpu.jsonl"
}
for s in "${scenes[@]}"; do
  bench "$s" cells "$work/$s.json" --env-estimator cells
  bench "$s" monte-carlo "$work/$s.json" --env-estimator monte-carlo
done
snake=(--mesh "$data/snake.glb" --pack "$data/x5.ktx2" --size "$size")
bench snake cells "${snake[@]}" --env-estimator cells
bench snake point "${snake[@]}" --lighting point
"$play" "$work/sphere-sky.json" --headless --env-estimator cells -q -o "$out/sphere-first.exr"
python3 - "$out/gpu.jsonl" "$size" > "$out/gpu.md" <<'EOF'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
ms = lambda v: "-" if v is None else f"{v:.1f}"
print(f"Adapter: {rows[0].get('adapter')}\n")
print(f"| scene ({sys.argv[2]}) | what | frame ms (median) | Lambert ms | ratio | first frame ms | setup ms | process s |")
print("|---|---|---|---|---|---|---|---|")
for r in rows:
    f, l = r.get("frame_ms_median"), r.get("lambert_frame_ms_median")
    ratio = f"{f / l:.1f}x" if f and l else "-"
    print(f"| {r['scene']} | {r['what']} | {ms(f)} | {ms(l)} | {ratio} | {ms(r.get('first_frame_ms'))} | {ms(r.get('setup_ms'))} | {r['process_s']} |")
EOF
cat "$out/gpu.md"
