#!/usr/bin/env bash
# Player accuracy and start-up at the scale of real scans (issue 11; docs/bench/play.md).
#
#   tools/sunbeam-play/bench/realscale.sh OUT_DIR [SIZE:PIXEL ...]
#
# For each synthetic Xenopeltis-like ridge field (443 nm tall, 1.55 um period,
# rough) of SIZE^2 pixels of PIXEL: sunbeam-pack with --response (pack and map
# build times, map size), the CPU reference of a front-lit sphere filling the
# frame (sunbeam-eval render --samples 16, linear EXR), then the player
# (response map, 1x and --supersample 2) and the former Cartesian table
# (--mode table: the baseline, built at start-up) against it: CIEDE2000 over lit
# pixels, and the player's start-up. One CSV row per size on stdout and in
# OUT_DIR/realscale.csv. Needs a release build (cargo build --release --workspace).
# Environment: RES (reference and frame size, default 128), PACK_FLAGS (e.g.
# "--model tiled", "--coherence 20um"), TABLE=0 (skip the table baseline: its
# start-up takes minutes at the large sizes), REF_SAMPLES (default 16),
# SUNBEAM_BIN (the folder of the binaries).
set -euo pipefail
out=${1:?usage: realscale.sh OUT_DIR [SIZE:PIXEL ...]}
shift
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=(256:31nm 1024:20nm 2048:20nm)
root=$(cd "$(dirname "$0")/../../.." && pwd)
bin=${SUNBEAM_BIN:-$(cd "$root" && cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release}
res=${RES:-128}
mkdir -p "$out"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(d=${TMPDIR:-/tmp}/sunbeam-xdg-$(id -u); mkdir -p -m 700 "$d"; echo "$d")}
csv="$out/realscale.csv"
echo "size,pixel,patch_um,pack_bytes,pack_s,map_grid,map_bytes,map_s,ref_s,startup_map_ms,startup_table_ms,map_1x_mean,map_1x_p99,map_1x_max,map_ss2_mean,map_ss2_p99,map_ss2_max,table_1x_mean,table_1x_p99,table_1x_max" | tee "$csv"
j() { python3 -c "import json,sys; d=json.load(sys.stdin); print($1)"; }
for sp in "${sizes[@]}"; do
  n=${sp%%:*}; px=${sp#*:}
  d="$out/$n-$px"; mkdir -p "$d"
  "$bin/sunbeam-import" synthetic:xenopeltis --synthetic-size "$n" --synthetic-pixel "$px" -o "$d/h.exr" -q
  # shellcheck disable=SC2086
  pj=$("$bin/sunbeam-pack" "$d/h.exr" -o "$d/p.ktx2" --response --json -q ${PACK_FLAGS:-})
  cat > "$d/scene.json" <<JSON
{ "camera": { "eye": [0, 0, 1.6], "target": [0, 0, 0], "fov_y_deg": 35 },
  "lights": [ { "direction": [0.15, 0.1, 1], "intensity": 1 } ],
  "meshes": [ { "mesh": "builtin:sphere", "pack": "p.ktx2", "base_color": [0.03, 0.03, 0.03], "diffuse_weight": 0.1 } ],
  "exposure": 0, "size": [$res, $res] }
JSON
  t0=$(date +%s.%N)
  "$bin/sunbeam-eval" render "$d/scene.json" --samples "${REF_SAMPLES:-16}" -o "$d/ref.exr"
  t1=$(date +%s.%N)
  cmp() { "$bin/sunbeam-play" "$d/scene.json" --headless -o "$d/$1.exr" --compare "$d/ref.exr" --json -q "${@:2}"; }
  m1=$(cmp map1)
  m2=$(cmp map2 --supersample 2)
  if [ "${TABLE:-1}" = 0 ]; then
    tb='{"setup_ms": -1, "ciede2000": {"mean": -1, "p99": -1, "max": -1}}'  # -1: not run
  else
    tb=$(cmp table1 --mode table)
  fi
  patch=$(python3 -c "import re; v=float(re.match(r'[0-9.]+','$px').group()); print(round($n*v/1000,2))")
  row="$n,$px,$patch,$(echo "$pj" | j 'd["bytes_written"]-d["response"]["bytes"]'),$(echo "$pj" | j 'round(d["pack_time_s"],2)'),$(echo "$pj" | j '"x".join(map(str,d["response"]["grid"]))'),$(echo "$pj" | j 'd["response"]["bytes"]'),$(echo "$pj" | j 'round(d["response"]["time_s"],2)'),$(python3 -c "print(round($t1-$t0,1))")"
  row="$row,$(echo "$m1" | j 'round(d["setup_ms"])'),$(echo "$tb" | j 'round(d["setup_ms"])')"
  for r in "$m1" "$m2" "$tb"; do
    row="$row,$(echo "$r" | j '"%.3f,%.3f,%.3f" % (d["ciede2000"]["mean"], d["ciede2000"]["p99"], d["ciede2000"]["max"])')"
  done
  echo "$row" | tee -a "$csv"
done
