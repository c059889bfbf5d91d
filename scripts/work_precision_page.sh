#!/usr/bin/env bash
# Regenerates docs/work_precision.md: work-precision of fixed against adaptive steps
# (Settings::step_control) on the double pendulum, the four-bar, the slider-crank, the
# clearance pendulum, the four-bar with three clearances and the C-60 trip, and the
# study of the slider-crank's plateau near 1e-4 m. Stages:
#   scenes  nscd_work_precision per scene, one run at a time (--jobs 1: wall times
#           compared within a table), the load before and after each
#   crank   scripts/analysis/slider_crank_study.py
#   scripts/work_precision_page.sh                 both (11 min 44 s at 7612adb on 2 shared cores)
#   WP_QUICK=1 scripts/work_precision_page.sh      coarser grids, shorter references
#   WP_SKIP="crank" scripts/work_precision_page.sh skip stages (their raw results in $OUT are reused)
#   WP_SCENES="double_pendulum fourbar" ...        only these scenes of the scenes stage
# Raw results go to $OUT (default build/work_precision); docs/work_precision.md is rewritten
# from scripts/templates/work_precision_template.md.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
OUT=${OUT:-$repo/build/work_precision}
bin=$ws/devel/lib/nscd_sim
mkdir -p "$OUT"
[ -n "${NSCD_NO_BUILD:-}" ] || "$repo/scripts/build.sh"
py=/usr/bin/python3
start=$(date +%s)
skip() { [[ " ${WP_SKIP:-} " == *" $1 "* ]]; }
# ran STAGE: records the date and commit a stage's raw results are made at (the page says
# which run each part comes from when stages are skipped).
ran() {
  local rev
  rev="$(git -C "$repo" rev-parse --short HEAD)"
  [ -z "$(git -C "$repo" status --porcelain -- . ':!docs')" ] || rev="$rev (with uncommitted changes)"
  printf 'date %s\ncommit %s\n' "$(date -u '+%Y-%m-%d %H:%M UTC')" "$rev" > "$OUT/ran_$1.info"
}

quick=${WP_QUICK:-}
# Fixed steps (each divides the scene's sample interval) and adaptive tolerances.
smooth_hs=1e-2,5e-3,2e-3,1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5
smooth_tols=1e-2,1e-3,1e-4,1e-5,1e-6,1e-7,1e-8
# The contact scenes' fixed grid starts at the adaptive runs' largest step (1e-3), so
# that the fixed front covers the adaptive runs' errors (no extrapolation above it).
contact_hs=1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6
contact_tols=1e-2,1e-3,1e-4,1e-5,1e-6
c60_hs=1e-5,5e-6,2e-6,1e-6
c60_tols=1e-2,1e-3,1e-4
smooth_ref=(--ref-adaptive 1e-10 --ref-tol 1e-12)
href=1e-7
if [ -n "$quick" ]; then
  smooth_hs=1e-2,1e-3,1e-4; smooth_tols=1e-3,1e-5; contact_hs=1e-4,1e-5; contact_tols=1e-3,1e-4
  c60_hs=1e-5,2e-6; c60_tols=1e-3; smooth_ref=(--ref-adaptive 1e-8 --ref-tol 1e-12); href=1e-6
fi

# scene NAME FILE DURATION SAMPLE_DT ARGS...: one nscd_work_precision run of the set.
scene() {
  local name=$1 file=$2 duration=$3 sample=$4
  shift 4
  [ -z "${WP_SCENES:-}" ] || [[ " $WP_SCENES " == *" $name "* ]] || return 0
  local args=(--scenes none --scene-file "$name=$repo/$file" --file-duration "$duration"
              --file-sample-dt "$sample" --jobs 1 --csv "$OUT/wp_$name.csv" "$@")
  echo "== $name"
  {
    echo "command nscd_work_precision ${args[*]//$repo\//}"
    echo "load_start $(cut -d' ' -f1-3 /proc/loadavg)"
  } > "$OUT/wp_$name.info"
  "$bin/nscd_work_precision" "${args[@]}" > "$OUT/wp_$name.orders.csv"
  echo "load_end $(cut -d' ' -f1-3 /proc/loadavg)" >> "$OUT/wp_$name.info"
}

if ! skip scenes; then
  ran scenes
  # Ideal joints, 1 s: the reference an adaptive run 100 times tighter than the tightest run.
  scene double_pendulum test/scenes/double_pendulum.urdf 1 1e-2 --hs "$smooth_hs" --tols 1e-10 \
    --adaptive-tols "$smooth_tols" --adaptive-dt 1e-2 "${smooth_ref[@]}"
  scene fourbar urdf/fourbar.urdf 1 1e-2 --hs "$smooth_hs" --tols 1e-10 \
    --adaptive-tols "$smooth_tols" --adaptive-dt 1e-2 "${smooth_ref[@]}"
  # Contacts, 0.2 s: the reference fixed steps of 1e-7 s (first order at impacts).
  scene slider_crank urdf/slider_crank.urdf 0.2 1e-3 --hs "$contact_hs" --tols 1e-8 \
    --adaptive-tols "$contact_tols" --adaptive-dt 1e-3 --href "$href"
  scene clearance_pendulum urdf/clearance_pendulum.urdf 0.2 1e-3 --hs "$contact_hs" --tols 1e-8 \
    --adaptive-tols "$contact_tols" --adaptive-dt 1e-3 --href "$href"
  scene fourbar_3clearances test/scenes/fourbar_3clearances.urdf 0.2 1e-3 --hs "$contact_hs" --tols 1e-8 \
    --adaptive-tols "$contact_tols" --adaptive-dt 1e-3 --href "$href"
  # The C-60 trip's first 10 ms (the touch, the release and C7's opening are inside), the
  # probe of scripts/c60_env.sh; compared at the end.
  probe=$(NSCD_RUN=/bin/true C60_OUT=$OUT/c60 bash -c "source '$repo/scripts/c60_env.sh'; echo \$C60_PROBE")
  scene c60_trip urdf/c60.urdf 0.010 1e-4 --command "$probe" --hs "$c60_hs" --tols 1e-8 \
    --adaptive-tols "$c60_tols" --adaptive-dt 1e-5 --href "$href"
fi

if ! skip crank; then
  echo "== slider-crank study"
  ran crank
  quick_arg=()
  [ -z "$quick" ] || quick_arg=(--quick)
  rm -f "$OUT"/crank_*.csv "$OUT"/crank_*.json
  $py "$repo/scripts/analysis/slider_crank_study.py" --bin "$bin" --scene "$repo/urdf/slider_crank.urdf" \
    --out "$OUT" "${quick_arg[@]}" > /dev/null
fi

# How long the stages took (kept from the last run that ran any).
skip scenes && skip crank || echo $(( $(date +%s) - start )) > "$OUT/elapsed.txt"
$py "$repo/scripts/analysis/work_precision_page.py" "$OUT" --template "$repo/scripts/templates/work_precision_template.md" \
  --page "$repo/docs/work_precision.md"
