#!/usr/bin/env bash
# Response-map size against error and frame time (the Pareto front of issue 11),
# for one case made by realscale.sh (its h.exr, scene.json and ref.exr):
#
#   tools/sunbeam-play/bench/budget.sh CASE_DIR [BUDGET ...]     (e.g. 4MiB 16MiB 64MiB)
#
# For each budget: sunbeam-pack --response --response-budget B (map grid, size,
# build time), the player against the case's reference (CIEDE2000 over lit
# pixels, 1x), and the frame time at 512 x 512 (15 frames) with Lambert in the
# same run. CSV on stdout.
set -euo pipefail
d=${1:?usage: budget.sh CASE_DIR [BUDGET ...]}
shift
budgets=("$@")
[ ${#budgets[@]} -gt 0 ] || budgets=(2MiB 8MiB 16MiB 32MiB 64MiB)
root=$(cd "$(dirname "$0")/../../.." && pwd)
bin=${SUNBEAM_BIN:-$(cd "$root" && cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release}
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(d=${TMPDIR:-/tmp}/sunbeam-xdg-$(id -u); mkdir -p -m 700 "$d"; echo "$d")}
j() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
echo "budget,grid,map_bytes,map_s,p99,max,mean,frame_ms,lambert_ms"
for b in "${budgets[@]}"; do
  pj=$("$bin/sunbeam-pack" "$d/h.exr" -o "$d/p.ktx2" --response --response-budget "$b" --json -q)
  c=$("$bin/sunbeam-play" "$d/scene.json" --headless -o "$d/budget.exr" --compare "$d/ref.exr" --json -q)
  f=$("$bin/sunbeam-play" "$d/scene.json" --bench --size 512x512 --frames 15 --json -q)
  l=$("$bin/sunbeam-play" "$d/scene.json" --bench --size 512x512 --frames 15 --lambert --json -q)
  echo "$b,$(echo "$pj" | j '"x".join(map(str,d["response"]["grid"]))'),$(echo "$pj" | j 'd["response"]["bytes"]'),$(echo "$pj" | j 'round(d["response"]["time_s"],1)'),$(echo "$c" | j '"%.3f,%.3f,%.3f" % (d["ciede2000"]["p99"], d["ciede2000"]["max"], d["ciede2000"]["mean"])'),$(echo "$f" | j 'round(d["frame_ms_median"],1)'),$(echo "$l" | j 'round(d["frame_ms_median"],1)')"
done
