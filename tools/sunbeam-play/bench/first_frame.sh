#!/usr/bin/env bash
# The player's first frame under an environment against the reference, over
# all lit, interior and edge pixels (issue 26; docs/bench/play.md "The cells'
# first frame, interior and edge").
#
#   tools/sunbeam-play/bench/first_frame.sh OUT_DIR PACK.ktx2 [FRAMES ...]
#
# A sphere filling a RES x RES frame (default 64), masked (MASKING, default
# smith), lit by ENV: `sky` (default: the built-in sky, sun 35 deg up) or the
# path of an equirectangular HDR image; BACKGROUND=environment draws it behind
# (default: black). The reference is `sunbeam-eval render --samples
# $REF_SAMPLES` (default 256) at seeds 1 and 2 and their mean; its own noise
# is seed 1 against seed 2. With CONVERGE=DE each seed is converged
# (`--converge DE`, docs/EVAL.md "A converged reference"; 0.15 makes issue
# 26's converged reference, minutes per seed) and seed 1 is the reference. The player renders with
# `--env-estimator cells --supersample $SUPERSAMPLE` (default 4) for each
# FRAMES (default 1 16) and is compared with the mean by `sunbeam-eval diff`.
# Prints a markdown table: CIEDE2000 p99 all / interior / edge, and seconds.
# SUNBEAM_BIN: the folder of the binaries (default: cargo's target/release).
set -euo pipefail
out=${1:?usage: first_frame.sh OUT_DIR PACK.ktx2 [FRAMES ...]}
pack=$(realpath "${2:?pack}")
shift 2
frames=("$@")
[ ${#frames[@]} -gt 0 ] || frames=(1 16)
root=$(cd "$(dirname "$0")/../../.." && pwd)
bin=${SUNBEAM_BIN:-$(cd "$root" && cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release}
res=${RES:-64}
ref_samples=${REF_SAMPLES:-256}
ss=${SUPERSAMPLE:-4}
env_kind=${ENV:-sky}
converge=()
[ -n "${CONVERGE:-}" ] && converge=(--converge "$CONVERGE")
background=""
case "${BACKGROUND:-}" in
  "") ;;
  environment) background='"background": "environment",' ;;
  *) echo "first_frame.sh: BACKGROUND must be environment or unset" >&2; exit 1 ;;
esac
mkdir -p "$out"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(d=${TMPDIR:-/tmp}/sunbeam-xdg-$(id -u); mkdir -p -m 700 "$d"; echo "$d")}
if [ "$env_kind" = sky ]; then
  env='"environment": { "sky": { "sun_elevation_deg": 35, "sun_azimuth_deg": 60, "turbidity": 3 }, "intensity": 1 }'
else
  env="\"environment\": { \"map\": \"$(realpath "$env_kind")\", \"intensity\": 1 }"
fi
s="$out/scene.json"
cat > "$s" <<JSON
{ "camera": { "eye": [0, 0, 2.4], "target": [0, 0, 0], "fov_y_deg": 26 },
  "meshes": [ { "mesh": "builtin:sphere", "pack": "$pack", "base_color": [0.05, 0.05, 0.05], "diffuse_weight": 0.2, "masking": "${MASKING:-smith}" } ],
  $env, $background "exposure": 4.64, "size": [$res, $res] }
JSON
p99s() { python3 -c "import json,sys; d=json.load(sys.stdin); print(' / '.join('%.2f' % d[k]['p99'] for k in ('all', 'interior', 'edge')))"; }
now() { date +%s.%N; }
echo "| what | seconds | CIEDE2000 p99 all / interior / edge |"
echo "|---|---|---|"
if [ ! -f "$out/ref.exr" ]; then
  t0=$(now)
  "$bin/sunbeam-eval" render "$s" --samples "$ref_samples" "${converge[@]}" --seed 1 -o "$out/ref1.exr" -q
  t1=$(now)
  "$bin/sunbeam-eval" render "$s" --samples "$ref_samples" "${converge[@]}" --seed 2 -o "$out/ref2.exr" -q
  if [ ${#converge[@]} -gt 0 ]; then
    cp "$out/ref1.exr" "$out/ref.exr"
  else
    "$bin/sunbeam-eval" render "$s" --samples "$ref_samples" --seed 1 --seed 2 -o "$out/ref.exr" -q
  fi
  echo "| reference seed 1 vs 2 ($ref_samples samples${CONVERGE:+, --converge $CONVERGE}) | $(echo "$t1 - $t0" | bc) | $("$bin/sunbeam-eval" diff "$out/ref1.exr" "$out/ref2.exr" --json | p99s) |" > "$out/ref.row"
fi
cat "$out/ref.row"
for n in "${frames[@]}"; do
  t0=$(now)
  "$bin/sunbeam-play" "$s" --headless --env-estimator cells --supersample "$ss" --frames "$n" -o "$out/play-$n.exr" 2>/dev/null
  t1=$(now)
  echo "| player, cells, $n frame(s), vs the reference | $(echo "$t1 - $t0" | bc) | $("$bin/sunbeam-eval" diff "$out/play-$n.exr" "$out/ref.exr" --json | p99s) |"
done
