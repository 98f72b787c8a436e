#!/usr/bin/env bash
# Where CI's time goes: run .ci/run (or read a log it wrote) with each line
# stamped by the seconds since the start, then list the test binaries and the
# tests that took longest.
#
#   scripts/ci-times.sh run LOG     # CI=true .ci/run, stamped into LOG, then the summary
#   scripts/ci-times.sh show LOG    # the summary of a stamped LOG
#
# libtest prints no duration per test on stable Rust, only "has been running
# for over 60 seconds" and "... ok": a test's time here is from 60 s before
# the first to the second, so tests under 60 s are not listed; a binary's
# time runs from its "Running" line to the next. Binaries run one after
# another, their tests two at a time on 2 cores: a binary whose last test
# runs alone leaves a core idle.
set -euo pipefail
mode=${1:?usage: ci-times.sh run|show LOG}
log=${2:?usage: ci-times.sh run|show LOG}
case "$mode" in
  run)
    cd "$(dirname "$0")/.."
    start=$(date +%s)
    set +e
    CI=true bash .ci/run 2>&1 | while IFS= read -r line; do
      echo "$(($(date +%s) - start)) $line"
    done > "$log"
    rc=${PIPESTATUS[0]}
    set -e
    echo "rc $rc in $(($(date +%s) - start)) s" >> "$log"
    ;;
  show) ;;
  *) echo "ci-times.sh: run or show, not $mode" >&2; exit 1 ;;
esac
echo "## test binaries, seconds (longest first)"
grep -E '^[0-9]+ +(Running|Doc-tests)' "$log" |
  awk '{ t = $1 + 0; if (name != "") printf "%6d %s\n", t - t0, name; t0 = t; $1 = ""; name = $0 }' |
  sort -rn | head -15 || true
echo "## tests of 60 s or more, seconds (longest first)"
awk '/has been running for over 60 seconds/ { s[$3] = $1 - 60 }
     / \.\.\. (ok|FAILED)$/ { if ($3 in s) printf "%6d %s\n", $1 - s[$3], $3 }' "$log" |
  sort -rn | head -25 || true
tail -1 "$log"
