#!/usr/bin/env bash
# The soak: 1e6 steps of one scene with resident memory and heap
# allocations sampled along the way, then a shorter run under valgrind massif.
# Usage: scripts/soak.sh [STEPS (default 1000000)] [MASSIF_STEPS (default 20000)] [SCENE]
# Output: $OUT (default build/perf)/soak.json, soak_memory.csv, massif.out, massif.txt
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
out=${OUT:-$repo/build/perf}
steps=${1:-1000000}
msteps=${2:-20000}
scene=${3:-$repo/urdf/clearance_pendulum.urdf}
mkdir -p "$out"
[ -n "${NSCD_NO_BUILD:-}" ] || "$repo/scripts/build.sh" >/dev/null
bin=$ws/devel/lib/nscd_sim/nscd_stress
status=0
"$bin" --soak "$steps" --soak-scene "$scene" --sample-every 10000 --soak-csv "$out/soak_memory.csv" \
  > "$out/soak.json" || status=$?
cat "$out/soak.json"
if command -v valgrind >/dev/null; then
  valgrind --tool=massif --massif-out-file="$out/massif.out" "$bin" --soak "$msteps" \
    --soak-scene "$scene" --sample-every 1000 > /dev/null 2> "$out/massif.log"
  ms_print "$out/massif.out" > "$out/massif.txt"
  # Heap at the peak and at the last snapshot: equal when nothing grows.
  /usr/bin/python3 - "$out/massif.out" <<'PY'
import re, sys
snaps = re.findall(r"mem_heap_B=(\d+)", open(sys.argv[1]).read())
heap = [int(s) for s in snaps]
print('{"massif_snapshots":%d,"heap_B_peak":%d,"heap_B_last":%d,"heap_B_at_half":%d}'
      % (len(heap), max(heap), heap[-1], heap[len(heap) // 2]))
PY
fi
exit $status
