#!/usr/bin/env bash
# Pack build benchmark: sunbeam-pack (Rust) against numpy/scipy in the same run.
# Usage: tools/sunbeam-pack/bench/run.sh [OUTDIR]   (needs /usr/bin/time, python3 with numpy+scipy)
set -euo pipefail
cd "$(dirname "$0")/../../.."
OUT=${1:-/tmp/sunbeam-pack-bench}
mkdir -p "$OUT"
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target}
cargo build --release -p sunbeam-pack --example pack_bench >&2
BIN=$CARGO_TARGET_DIR/release/examples/pack_bench
rss() { grep "Maximum resident set size" "$1" | awk '{print $NF}'; }
echo "M N impl seconds peak_rss_MiB output_MiB"
for M in 512 1024 2048; do
  for N in 20 40; do
    /usr/bin/time -v "$BIN" "$M" "$N" "$OUT/p.ktx2" 2 >"$OUT/r.json" 2>"$OUT/r.time"
    /usr/bin/time -v python3 tools/sunbeam-pack/bench/bench_numpy.py "$M" "$N" "$OUT/p.npy" >"$OUT/n.json" 2>"$OUT/n.time"
    ob=$(stat -c %s "$OUT/p.ktx2")
    python3 - "$M" "$N" "$OUT" "$(rss "$OUT/r.time")" "$(rss "$OUT/n.time")" "$ob" <<'PY'
import json, sys
M, N, out, rr, nr, ob = sys.argv[1:]
r = json.load(open(out + "/r.json")); n = json.load(open(out + "/n.json"))
mib = lambda kb: int(kb) / 1024
inp = int(M) * int(M) * 4 / 2**20
o = int(ob) / 2**20
print(f"{M} {N} rust {r['total_s']:.2f} {mib(rr):.0f} {o:.0f} (build {r['build_s']:.2f}s, input f32 {inp:.0f} MiB, peak/(in+out) {mib(rr)/(inp+o):.2f})")
print(f"{M} {N} numpy {n['total_s']:.2f} {mib(nr):.0f} {o:.0f} (speed-up {n['total_s']/r['total_s']:.2f}x)")
PY
  done
done
