#!/usr/bin/env bash
# Fuzz every sunbeam-afm parser for SECONDS each (default 120), one after the other.
# Seeds: ../shared/data samples and small synthetic files (seeds.py), in fuzz/corpus/
# (ignored by git: the samples' licences keep them out of the repository).
# Needs cargo-fuzz (`cargo install cargo-fuzz`) and a nightly toolchain, or
# RUSTC_BOOTSTRAP=1 with stable. Prints one summary line per target.
set -euo pipefail
cd "$(dirname "$0")"
secs=${1:-120}
shift || true
targets=${*:-"nanoscope gwy gsf ibw sxm park_tiff jpk png tiff bmp ascii xyz nid mi wsxm mdt detect envmap response_files"}
python3 seeds.py corpus "${SUNBEAM_SHARED_DATA:-../../shared/data}"
tc=+nightly
rustup run nightly true 2>/dev/null || { tc=; export RUSTC_BOOTSTRAP=1; }
cargo $tc fuzz build -O ${CARGO_TARGET_DIR:+--target-dir "$CARGO_TARGET_DIR"}
for t in $targets; do
    log=artifacts/$t.log
    mkdir -p artifacts/$t
    cargo $tc fuzz run -O ${CARGO_TARGET_DIR:+--target-dir "$CARGO_TARGET_DIR"} "$t" "corpus/$t" -- \
        -max_total_time="$secs" -max_len=3000000 -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="artifacts/$t/" >"$log" 2>&1 || echo "$t: FAILED (see fuzz/$log)"
    execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' || echo '?')
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
    echo "$t: ${secs}s, $execs execs, $cov, crashes: $(ls artifacts/$t | wc -l)"
done
