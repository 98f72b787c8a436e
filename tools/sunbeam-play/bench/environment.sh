#!/usr/bin/env bash
# The player's environment lighting against the reference (issue 13;
# docs/bench/play.md "Environment mode").
#
#   tools/sunbeam-play/bench/environment.sh OUT_DIR PACK.ktx2 SNAKE.glb [FRAMES ...]
#
# Two scenes under the built-in sky (sun 35 deg up): a sphere filling the frame
# and the baked snake (examples/sky-scene.json.in's camera). For each: the
# reference `sunbeam-eval render --samples $REF_SAMPLES` at seeds 1 and 2 and
# their mean (the issue's reference), the seed-to-seed CIEDE2000 (the
# reference's own noise), then the player's settled frame (`--headless --frames
# N`) for each N against the mean, and the player's frame time while moving
# (`--bench`, the sum reset every frame, against `--lambert` in the same run) at
# 512 x 512. Prints a markdown table. Environment: RES (the sphere's frame
# size, default 64), SNAKE_W and SNAKE_H (the snake's, default 384 x 216),
# REF_SAMPLES (default 4096: the sub-pixel positions are jittered by the seed,
# and a silhouette needs thousands of them; above 256 they cost little more),
# SCENES (default "sphere snake"), SUPERSAMPLE (the
# player's --supersample, default 1), SPHERE_MASKING and SNAKE_MASKING (the
# meshes' "masking", default off and smith: docs/LIGHTING.md "Grazing views:
# masking"), SUNBEAM_BIN (the folder of the binaries). The skin reflects
# absolutely (4 % head-on): base colour 0.03 x F(0) and exposure -1.5 + 4.6 EV
# keep the frames as bright as the figures measured under the relative model.
set -euo pipefail
out=${1:?usage: environment.sh OUT_DIR PACK.ktx2 SNAKE.glb [FRAMES ...]}
pack=$(realpath "${2:?pack}")
snake=$(realpath "${3:?snake mesh}")
shift 3
frames=("$@")
[ ${#frames[@]} -gt 0 ] || frames=(16 64 256 1024)
root=$(cd "$(dirname "$0")/../../.." && pwd)
bin=${SUNBEAM_BIN:-$(cd "$root" && cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release}
res=${RES:-64}
# The snake is a few percent of its frame: at 64 px high it is 3-5 px thick
# and nearly every pixel is a silhouette; 384 x 216 gives it ~15 px.
snake_w=${SNAKE_W:-384}
snake_h=${SNAKE_H:-216}
ref_samples=${REF_SAMPLES:-4096}
sphere_masking=${SPHERE_MASKING:-off}
snake_masking=${SNAKE_MASKING:-smith}
mkdir -p "$out"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(d=${TMPDIR:-/tmp}/sunbeam-xdg-$(id -u); mkdir -p -m 700 "$d"; echo "$d")}
sky='"environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 70, "turbidity": 3 }, "intensity": 1 }'
cat > "$out/sphere.json" <<JSON
{ "camera": { "eye": [0, 0.25, 1.2], "target": [0, 0, 0] },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "$pack", "base_color": [0.0012, 0.0012, 0.0014], "diffuse_weight": 0.15, "masking": "$sphere_masking" } ],
  $sky, "exposure": 3.1, "size": [$res, $res] }
JSON
cat > "$out/snake.json" <<JSON
{ "camera": { "eye": [0.0, -0.55, 1.05], "target": [0.0, -0.01, 0.0], "up": [0, 1, 0], "fov_y_deg": 28 },
  "meshes": [ { "mesh": "$snake", "pack": "$pack", "base_color": [0.0012, 0.0012, 0.0014], "diffuse_weight": 0.15, "masking": "$snake_masking" } ],
  $sky, "exposure": 3.1, "size": [$snake_w, $snake_h] }
JSON
cie() { sed -E 's/.*mean ([0-9.]+) p99 ([0-9.]+) max ([0-9.]+).*/\1 \/ \2 \/ \3/'; }
j() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
echo "| scene | what | seconds | CIEDE2000 mean / p99 / max |"
echo "|---|---|---|---|"
for scene in ${SCENES:-sphere snake}; do
  s="$out/$scene.json"
  # The references are kept in OUT_DIR: a second run with other FRAMES reuses them.
  if [ ! -f "$out/$scene-ref.exr" ]; then
    t0=$(date +%s.%N)
    "$bin/sunbeam-eval" render "$s" --samples "$ref_samples" --seed 1 -o "$out/$scene-ref1.exr" -q
    t1=$(date +%s.%N)
    d=$("$bin/sunbeam-eval" render "$s" --samples "$ref_samples" --seed 2 -o "$out/$scene-ref2.exr" --compare "$out/$scene-ref1.exr" | cie)
    echo "| $scene | reference seed 2 vs 1 ($ref_samples samples) | $(echo "$t1 - $t0" | bc) | $d |" > "$out/$scene-ref.row"
    "$bin/sunbeam-eval" render "$s" --samples "$ref_samples" --seed 1 --seed 2 -o "$out/$scene-ref.exr" -q
  fi
  cat "$out/$scene-ref.row"
  for n in "${frames[@]}"; do
    t0=$(date +%s.%N)
    r=$("$bin/sunbeam-play" "$s" --headless --supersample "${SUPERSAMPLE:-1}" --frames "$n" -o "$out/$scene-play-$n.exr" --compare "$out/$scene-ref.exr" --json 2>/dev/null)
    t1=$(date +%s.%N)
    echo "| $scene | player, $n frames, vs the mean of the two seeds | $(echo "$t1 - $t0" | bc) | $(echo "$r" | j "'%.2f / %.2f / %.2f' % (d['ciede2000']['mean'], d['ciede2000']['p99'], d['ciede2000']['max'])") |"
  done
done
sed -e "s/\[$res, $res\]/[512, 512]/" "$out/sphere.json" > "$out/sphere512.json"
r=$("$bin/sunbeam-play" "$out/sphere512.json" --bench --frames 10 --json 2>/dev/null)
echo
echo "Frame time while moving, 512 x 512: $(echo "$r" | j "'%.0f ms, --lambert %.0f ms in the same run: %.2fx' % (d['frame_ms_median'], d['lambert_frame_ms_median'], d['ratio_to_lambert'])")"
