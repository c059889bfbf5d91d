#!/usr/bin/env bash
# C-60 sensitivity: the bench and the trip with ideal joints (x0), all clearances x0.1, x0.2, x0.5,
# x1, x2 and all friction coefficients x0.5, x1.5. Scene variants are generated into out/ by
# c60_scene.py; runs C60_JOBS (default 2) cases at a time; writes docs/c60_sensitivity.md with
# the date and the commit. C60_CASES="name:cscale:fscale ..." runs a subset.
#   scripts/c60_sensitivity.sh
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
cases=${C60_CASES:-"c0:0:1 c01:0.1:1 c02:0.2:1 c05:0.5:1 c1:1:1 c2:2:1 f05:1:0.5 f15:1:1.5"}
run_case() {
  local name=$1 cs=$2 fs=$3
  $PY "$C60_REPO/scripts/c60_model/c60_scene.py" --out "$C60_OUT/c60_sens_$name.urdf" --clearance-scale $cs --friction-scale $fs
  $PY "$C60_REPO/scripts/c60_model/c60_scene.py" --out "$C60_OUT/c60_sens_${name}_bench.urdf" --bench --clearance-scale $cs --friction-scale $fs
  C60_TAG=sens_${name}_trip C60_PNG= bash "$C60_REPO/scripts/c60_trip.sh" "$C60_OUT/c60_sens_$name.urdf" > /dev/null
  C60_TAG=sens_${name}_bench C60_PNG= bash "$C60_REPO/scripts/c60_bench.sh" "$C60_OUT/c60_sens_${name}_bench.urdf" > /dev/null
  echo "done $name"
}
jobs_max=${C60_JOBS:-2}
for c in $cases; do
  IFS=: read -r name cs fs <<< "$c"
  run_case "$name" "$cs" "$fs" &
  while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do sleep 1; done
done
wait
commit=$(git -C "$C60_REPO" rev-parse --short HEAD 2>/dev/null || echo unknown)
git -C "$C60_REPO" diff --quiet HEAD -- 2>/dev/null || commit="$commit+changes"
$PY "$C60_REPO/scripts/analysis/c60_sensitivity.py" "$C60_OUT" "$C60_DOCS/c60_sensitivity.md" "$(date -u +%Y-%m-%d)" "$commit"
