#!/usr/bin/env bash
# Builds and runs the step benchmarks; extra arguments go to Google Benchmark
# (e.g. --benchmark_filter=Pendulum). Prints µs per step per scene.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
"$repo/scripts/build.sh" >/dev/null
exec "$ws/devel/lib/nscd_sim/nscd_bench" --benchmark_min_time=0.2 "$@"
