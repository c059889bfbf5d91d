#!/usr/bin/env bash
# The long stress suite: N randomised clearance pendulums, run
# twice (once on all cores, once on one thread) and compared byte for byte.
# Usage: scripts/stress.sh [--runs N] [--seed S] [--steps K]   (default 1000 runs)
# Output: $OUT (default build/perf)/stress.csv, stress_rerun.csv, stress_summary.json
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
out=${OUT:-$repo/build/perf}
mkdir -p "$out"
[ -n "${NSCD_NO_BUILD:-}" ] || "$repo/scripts/build.sh" >/dev/null
bin=$ws/devel/lib/nscd_sim/nscd_stress
status=0
"$bin" "$@" --csv "$out/stress.csv" --quiet > "$out/stress_summary.json" || status=$?
cat "$out/stress_summary.json"
"$bin" "$@" --jobs 1 --csv "$out/stress_rerun.csv" --quiet > /dev/null || true
if cmp -s "$out/stress.csv" "$out/stress_rerun.csv"; then
  echo "rerun (1 thread): bit-identical ($(wc -l < "$out/stress.csv") lines, $(sha256sum < "$out/stress.csv" | cut -c1-16))"
else
  echo "rerun (1 thread): DIFFERENT"; status=1
fi
exit $status
