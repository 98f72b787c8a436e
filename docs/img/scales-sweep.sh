#!/usr/bin/env bash
# The pictures of docs/BAKE.md "Scales": one strip per scale parameter
# (docs/img/scales-sweep-PARAM.png), four renders of a short section of the demo
# snake by the reference (sunbeam-eval render), the parameter varied from left to
# right and every other parameter at the Xenopeltis values of the demo
# (examples/Makefile SCALES_xeno). Composed with `sunbeam-eval sheet`.
#
#   docs/img/scales-sweep.sh [PACK] [OUTDIR]
#
# PACK: the Xenopeltis pack (default examples/out/xeno.ktx2, from `make demo`);
# OUTDIR: where the PNGs go (default docs/img). BIN (default target/release),
# SIZE (160x120) and SAMPLES (1) from the environment; PARAMS (default: all)
# names the strips to make, e.g. PARAMS=keel. About 25 renders of 15 s each on 2 cores.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
BIN=${BIN:-$root/target/release}
SIZE=${SIZE:-160x120}
SAMPLES=${SAMPLES:-1}
pack=$(realpath "${1:-$root/examples/out/xeno.ktx2}")
out=$(realpath "${2:-$root/docs/img}")
[ -f "$pack" ] || { echo "scales-sweep.sh: no pack '$pack' (run make demo first)" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/scales-sweep.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

# The demo's Xenopeltis (examples/Makefile SCALES_xeno); each sweep replaces one flag.
declare -A base=([rows]=20 [length]=1.0 [overlap]=0.3 [dome]=0.06 [keel]=0 [tilt]=6 [tilt-jitter]=4 [ridge-jitter]=6)
declare -A sweep=(
  [rows]="10 15 20 30"
  [length]="0.6 1.0 1.6 2.4"
  [overlap]="0 0.15 0.3 0.5"
  [dome]="0 0.06 0.15 0.3"
  [keel]="0 0.02 0.04 0.08"
  [tilt]="-10 0 6 20"
  [tilt-jitter]="0 4 10 20"
  [ridge-jitter]="0 6 20 45"
)
all="rows length overlap dome keel tilt tilt-jitter ridge-jitter"
order=${PARAMS:-$all}

# A short stretch of the back (where the spine runs along +x, near x = 0.1),
# one point light from the head's side and above. The base colour is lighter
# and more diffuse than the demo's dark skin (0.03, weight 0.15) so that the
# scales' shapes show in the shading, not only in the sparse glints.
cat > "$tmp/scene.json" <<EOF
{
  "camera": { "eye": [0.10, -0.21, 0.12], "target": [0.10, -0.115, 0.025], "up": [0, 0, 1], "fov_y_deg": 30 },
  "lights": [ { "direction": [0.7, -0.3, 0.65], "intensity": 1, "spectrum": "D65" } ],
  "meshes": [
    { "mesh": "snake.glb", "pack": "$pack", "base_color": [0.06, 0.06, 0.065], "diffuse_weight": 0.6 }
  ],
  "exposure": 3.0,
  "background": [0.0012, 0.0012, 0.0015],
  "size": [160, 120]
}
EOF

for p in $order; do
  pngs=()
  for v in ${sweep[$p]}; do
    flags=(--scales --scale-texels 16)
    for q in $all; do
      x=${base[$q]}; [ "$q" = "$p" ] && x=$v
      flags+=("--scale-$q" "$x")
    done
    # One render per distinct flag set (the demo's values recur in every strip).
    key=$(printf '%s_' "${flags[@]}" | tr -c 'A-Za-z0-9._-' '_')
    if [ ! -f "$tmp/$key.png" ]; then
      "$BIN/sunbeam-bake" --generate-snake "${flags[@]}" -o "$tmp/snake.glb" -q
      "$BIN/sunbeam-eval" render "$tmp/scene.json" --size "$SIZE" --samples "$SAMPLES" -o "$tmp/$key.png" -q
    fi
    pngs+=("$tmp/$key.png")
  done
  "$BIN/sunbeam-eval" sheet --columns 4 -o "$out/scales-sweep-$p.png" "${pngs[@]}" -q
  echo "scales-sweep-$p.png: --scale-$p ${sweep[$p]}"
done
