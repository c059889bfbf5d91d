#!/usr/bin/env bash
# Regenerates docs/performance.md and its figures with one command. Stages:
#   c60     the C-60 scenarios, both models, dt 1e-5 and 1e-6 (scripts/c60_solver_bench.sh)
#   c60dt   the C-60 trip against dt, reference 1e-7 (scripts/analysis/c60_trip_convergence.py)
#   wp      work-precision: small scenes, the slider-crank, the C-60 trip and bench
#   stress  the stress suite, seed 1 (+ bit-identical rerun on one thread)
#   seeds   the stress suite, seeds 2 and 3
#   soak    1e6 steps (+ massif)
#   sweep   a sharded sweep merged and checked against the unsharded one
#   speed   the C-60 trip (dt 1e-5, 1e-6) and 100 ms at rest, 3 times each, wall and CPU time
#   bench   the skip benchmarks (Google Benchmark)
#   scripts/performance.sh            full run (28 min 28 s on 2 cores at a load of 9-15, 2026-11-27)
#   PERF_QUICK=1 scripts/performance.sh   a few minutes: coarser grids, fewer runs, no C-60 dt 1e-6
#   PERF_SKIP="wp stress ..."            skip stages (their previous results in $OUT are reused)
#   PERF_C60=0                           leave the C-60 trip and bench out of the work-precision set
# Raw results go to $OUT (default build/perf); docs/*.png and docs/performance.md are rewritten.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
export OUT=${OUT:-$repo/build/perf}
bin=$ws/devel/lib/nscd_sim
mkdir -p "$OUT"
[ -n "${NSCD_NO_BUILD:-}" ] || "$repo/scripts/build.sh"
export NSCD_NO_BUILD=1
py=/usr/bin/python3
start=$(date +%s)
skip() { [[ " ${PERF_SKIP:-} " == *" $1 "* ]]; }
# ran STAGE: records the commit, date and load a stage's raw results were made at, so that a
# page made with PERF_SKIP says which of its figures come from an earlier run.
ran() {
  local changed=""
  [ -z "$(git -C "$repo" status --porcelain --untracked-files=no -- . ':!docs')" ] || changed=" with uncommitted changes"
  echo "$(git -C "$repo" rev-parse --short HEAD)$changed|$(date -u '+%Y-%m-%d %H:%M UTC')|$(cut -d' ' -f1 /proc/loadavg)" \
    > "$OUT/ran_$1.txt"
}

if [ -n "${PERF_QUICK:-}" ]; then
  wp_args=(--hs 1e-3,1e-4,1e-5 --href 1e-6 --tols 1e-4,1e-8)
  crank_args=(--hs 1e-4,1e-5 --href 1e-6)
  stress_runs=200; soak_steps=100000; massif_steps=5000
  c60_args=(--quick); c60dt_args=(--dts 1e-4,1e-5 --ref 1e-6)
else
  wp_args=()
  crank_args=(--hs 1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6 --href 1e-7)
  stress_runs=${PERF_STRESS_RUNS:-1000}; soak_steps=${PERF_SOAK_STEPS:-1000000}; massif_steps=20000
  c60_args=(); c60dt_args=(--dts 1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6,5e-7,2.5e-7 --ref 1e-7)
fi
# The load while the stages run (wall times are of a shared machine).
cut -d' ' -f1-3 /proc/loadavg > "$OUT/load_start.txt"

if ! skip c60; then
  echo "== C-60 scenarios (scripts/c60_solver_bench.sh ${c60_args[*]})"
  NSCD_WS=$ws "$repo/scripts/c60_solver_bench.sh" "${c60_args[@]}" | tee "$OUT/c60_solver.txt"
  ran c60
fi

if ! skip c60dt; then
  echo "== C-60 trip against dt"
  NSCD_WS=$ws $py "$repo/scripts/analysis/c60_trip_convergence.py" "${c60dt_args[@]}" \
    --out "$OUT/c60_dt" --json "$OUT/c60_dt.json" | tee "$OUT/c60_dt.md"
  ran c60dt
fi

if ! skip wp; then
echo "== work-precision"
# C-60 trip (scripts/c60_trip.sh: urdf/c60.urdf, 10 ms, the probe schedule of
# scripts/c60_env.sh): the h = 1e-6 reference (1e4 steps) and the grid take about
# a minute on 2 cores. PERF_C60=0 leaves it out.
# The C-60 bench (scripts/c60_bench.sh: urdf/c60_bench.urdf, 54 ms, the table schedule
# of scripts/c60_env.sh) the same way: ~40 s more.
rm -f "$OUT/work_precision_c60.csv" "$OUT/work_precision_c60_bench.csv"
if [ "${PERF_C60:-1}" != 0 ] && [ -f "$repo/urdf/c60.urdf" ] && [ -f "$repo/scripts/c60_env.sh" ]; then
  c60var() { NSCD_RUN=/bin/true C60_OUT=$OUT/c60 bash -c "source '$repo/scripts/c60_env.sh'; echo \$$1"; }
  "$bin/nscd_work_precision" --scenes none --scene-file "c60_trip=$repo/urdf/c60.urdf" \
    --file-duration 0.010 --file-sample-dt 1e-4 --command "$(c60var C60_PROBE)" \
    --hs 1e-4,5e-5,2e-5,1e-5 --href 1e-6 --tols 1e-4,1e-8 --csv "$OUT/work_precision_c60.csv" \
    > "$OUT/work_precision_c60_orders.csv"
  "$bin/nscd_work_precision" --scenes none --scene-file "c60_bench=$repo/urdf/c60_bench.urdf" \
    --file-duration 0.054 --file-sample-dt 1e-4 --command "$(c60var C60_TABLE)" \
    --hs 1e-4,5e-5,2e-5,1e-5 --href 1e-6 --tols 1e-4,1e-8 --csv "$OUT/work_precision_c60_bench.csv" \
    > "$OUT/work_precision_c60_bench_orders.csv"
fi
# The slider-crank (ideal joints turning fast), 0.2 s: the h = 1e-7 reference (2e6 steps) ~30 s.
"$bin/nscd_work_precision" --scenes none --scene-file "slider_crank=$repo/urdf/slider_crank.urdf" \
  --file-duration 0.2 "${crank_args[@]}" --tols 1e-8 --csv "$OUT/work_precision_crank.csv" \
  > "$OUT/work_precision_crank_orders.csv"
"$bin/nscd_work_precision" "${wp_args[@]}" --csv "$OUT/work_precision.csv" \
  > "$OUT/work_precision_orders.csv"
for f in "$OUT/work_precision_crank.csv" "$OUT/work_precision_c60.csv" "$OUT/work_precision_c60_bench.csv"; do
  if [ -f "$f" ]; then tail -n +2 "$f" >> "$OUT/work_precision.csv"; fi  # one CSV for the plots
done
ran wp
fi
$py "$repo/scripts/analysis/work_precision.py" "$OUT/work_precision.csv" --png "$repo/docs/work_precision.png" \
  --order-png "$repo/docs/work_precision_h.png" --table "$OUT/work_precision.md"

if ! skip stress; then
  echo "== stress ($stress_runs runs)"
  "$repo/scripts/stress.sh" --runs "$stress_runs" > "$OUT/stress.txt" || true
  cat "$OUT/stress.txt"
  ran stress
fi

if ! skip seeds; then
  for seed in 2 3; do
    echo "== stress, seed $seed ($stress_runs runs)"
    "$bin/nscd_stress" --runs "$stress_runs" --seed $seed --csv "$OUT/stress_seed$seed.csv" --quiet \
      > "$OUT/stress_seed$seed.json" || true
    cat "$OUT/stress_seed$seed.json"
  done
  ran seeds
fi

if ! skip soak; then
  echo "== soak ($soak_steps steps)"
  "$repo/scripts/soak.sh" "$soak_steps" "$massif_steps" > "$OUT/soak.txt" || true
  cat "$OUT/soak.txt"
  ran soak
fi

if ! skip sweep; then
echo "== sweep: 3 shards merged vs one run"
sweep=(--param radial=log:1e-6:1e-3:4 --param mu=0,0.3,1 --param e=0,0.5 --duration 0.05)
scene=$repo/urdf/clearance_pendulum.urdf
t0=$(date +%s%N)
"$bin/nscd_sweep" "$scene" "${sweep[@]}" --jobs 1 --quiet --csv "$OUT/sweep_1core.csv"
t1=$(date +%s%N)
"$bin/nscd_sweep" "$scene" "${sweep[@]}" --quiet --csv "$OUT/sweep_allcores.csv"
t2=$(date +%s%N)
for i in 0 1 2; do
  "$bin/nscd_sweep" "$scene" "${sweep[@]}" --shard $i/3 --jobs 1 --no-timing --quiet --csv "$OUT/sweep_shard$i.csv" &
done
wait
"$bin/nscd_sweep" --merge "$OUT"/sweep_shard{0,1,2}.csv --quiet > "$OUT/sweep_merged.csv"
"$bin/nscd_sweep" "$scene" "${sweep[@]}" --no-timing --quiet --csv "$OUT/sweep_whole.csv"
if cmp -s "$OUT/sweep_merged.csv" "$OUT/sweep_whole.csv"; then same=yes; else same=no; fi
echo "{\"runs\":$(($(wc -l < "$OUT/sweep_whole.csv") - 1)),\"wall_1core_ms\":$(( (t1 - t0) / 1000000 )),\"wall_allcores_ms\":$(( (t2 - t1) / 1000000 )),\"cores\":$(nproc),\"merged_equals_whole\":\"$same\"}" \
  | tee "$OUT/sweep.json"
  ran sweep
fi

if ! skip bench; then
  echo "== skip benchmarks"
  "$bin/nscd_bench" --benchmark_filter='Journal|ClearancePendulum|Frictionless' --benchmark_min_time=0.2 \
    --benchmark_repetitions=3 --benchmark_report_aggregates_only=true --benchmark_format=json \
    > "$OUT/bench.json"
  "$bin/nscd_bench_markers" --benchmark_min_time=0.2 --benchmark_repetitions=3 \
    --benchmark_report_aggregates_only=true --benchmark_format=json > "$OUT/bench_markers.json"
  ran bench
fi

if ! skip speed; then
  echo "== C-60 speed: the trip at dt 1e-5 and 1e-6, 100 ms at rest; 3 runs each"
  echo "run,rep,steps,wall_s,cpu_s,iters_mean" > "$OUT/speed.csv"
  probe=$(NSCD_RUN=/bin/true C60_OUT=$OUT/c60 bash -c "source '$repo/scripts/c60_env.sh'; echo \$C60_PROBE")
  for rep in 1 2 3; do
    for run in trip_1e-5 trip_1e-6 rest_1e-5; do
      case $run in
        trip_*) args=(--duration 0.0207 --command "$probe" --dt "${run#trip_}") ;;
        rest_*) args=(--duration 0.1 --dt "${run#rest_}") ;;
      esac
      # CPU time of the whole process (scene loading and assembly included), wall time of the stepping.
      /usr/bin/time -f "%U %S" -o "$OUT/speed_time.txt" "$bin/nscd_run" "$repo/urdf/c60.urdf" "${args[@]}" --quiet \
        > "$OUT/speed_run.json"
      $py -c "
import json, sys
d = json.loads(open(sys.argv[1]).read().strip().splitlines()[-1])
u, s = map(float, open(sys.argv[2]).read().split()[-2:])
print('%s,%s,%d,%.4f,%.4f,%.3f' % (sys.argv[3], sys.argv[4], d['steps'], d['wall_s'], u + s, d['iters_mean']))" \
        "$OUT/speed_run.json" "$OUT/speed_time.txt" "$run" "$rep" | tee -a "$OUT/speed.csv"
    done
  done
  ran speed
fi

cut -d' ' -f1-3 /proc/loadavg > "$OUT/load_end.txt"
echo "== report"
$py "$repo/scripts/analysis/performance_report.py" --out "$OUT" --docs "$repo/docs" --elapsed $(( $(date +%s) - start ))
echo "wrote $repo/docs/performance.md"
