#!/usr/bin/env bash
# Runs the rostests (and the ROS tools smoke test) N times in a row (default 5) while
# two busy loops load both cores: a check that no rostest depends on the machine's speed.
# Needs a built workspace (scripts/build.sh tests). Prints one line per round and a total.
#   scripts/rostests_under_load.sh [N]
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
export ROS_HOME=${ROS_HOME:-$ws/ros_home}
rounds=${1:-5}
[ -d "$ws/build" ] || { echo "no build in $ws: run scripts/build.sh tests" >&2; exit 2; }
loads=()
for _ in 1 2; do ( while :; do :; done ) & loads+=($!); done
trap 'kill "${loads[@]}" 2>/dev/null' EXIT
total_failed=0
for ((r = 1; r <= rounds; r++)); do
  log=$ws/rostests_under_load_$r.log
  (cd "$ws/build" && ctest -R 'rostest|ros_tools_smoke' --output-on-failure -j2 > "$log" 2>&1) || true
  passed=$(grep -Ec 'Test +#[0-9]+: .* +Passed' "$log" || true)
  failed=$(grep -Ec 'Test +#[0-9]+: .*(\*\*\*|Failed|Not Run)' "$log" || true)
  echo "round $r/$rounds (two busy loops): $passed passed, $failed failed  ($log)"
  total_failed=$((total_failed + failed))
done
echo "rostests under load: $rounds rounds, $total_failed failures"
[ "$total_failed" -eq 0 ]
