#!/usr/bin/env bash
# The main job: install what is missing, build, and run the demo headless,
# printing its summary (JSON) and writing its CSV to out/.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
bash "$repo/scripts/deps.sh"
bash "$repo/scripts/build.sh"
out=${NSCD_OUT:-$repo/out}
mkdir -p "$out"
run="$ws/devel/lib/nscd_sim/nscd_run"
echo "== clearance pendulum: 1 s, h = 1e-5, 50 µm radial clearance, mu 0.1"
"$run" "$repo/urdf/clearance_pendulum.urdf" --duration 1 --csv "$out/clearance_pendulum.csv" --every 100
echo "CSV: $out/clearance_pendulum.csv"
