#!/usr/bin/env bash
# The C-60's friction-contact problems as FCLib problems, solved by our solver and
# by Siconos's fc3d solvers (docs/fclib.md, "The C-60's problems").
#   scripts/c60_fclib.sh [OUT_DIR]        (default build/c60_fclib)
# Needs the optional Siconos/FCLib packages (scripts/install_siconos.sh) and a
# build made after installing them (scripts/build.sh).
# 1. dumps, with nscd_run --dump-problems: every solve the engine leaves unconverged
#    in the trip, the handle and the bench at dt 1e-5 and 1e-6, and every 250th step
#    of the trip at dt 1e-5 (latched, touching, releasing, after the opening); and
#    tools/fclib/c60_hard (handle steps at dt 1e-5 that earlier builds left unconverged);
# 2. converts each to FCLib (nscd_fclib --from-nscd: the probe's bilateral rows
#    condensed out);
# 3. solves each in its own process (a solver that crashes costs one row) at 1e-8
#    and 1e-10 (Siconos's error measure) with ours, NSGS, NSN-AC, NSN-FB and PROX;
# 4. writes OUT_DIR/fclib.csv and the tables OUT_DIR/fclib.md.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
made_by="${OPENBLAS_NUM_THREADS:+OPENBLAS_NUM_THREADS=$OPENBLAS_NUM_THREADS }scripts/c60_fclib.sh $*" started=$(date +%s) load_start=$(cut -d' ' -f1 /proc/loadavg)
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
bin=$ws/devel/lib/nscd_sim
out=${1:-$repo/build/c60_fclib}
if [ ! -x "$bin/nscd_fclib" ]; then
  echo "no $bin/nscd_fclib: run scripts/install_siconos.sh, then scripts/build.sh" >&2
  exit 1
fi
source "$repo/scripts/c60_env.sh"
rm -rf "$out"
mkdir -p "$out/dump" "$out/problems"
run() {  # tag scene duration dt when command...
  local tag=$1 scene=$2 dur=$3 dt=$4 when=$5
  shift 5
  mkdir -p "$out/dump/$tag"
  "$bin/nscd_run" "$repo/urdf/$scene" --duration "$dur" --dt "$dt" --quiet \
    --dump-problems "$out/dump/$tag" --dump-when "$when" "$@" > "$out/dump/$tag.json"
}
probe="probe=0:0,0.0007:0,0.0207:0.004"
handle="handle=0:0,0.004:0,0.014:1.2,0.020:1.2,0.030:0,0.040:0"
for dt in 1e-5 1e-6; do
  run "trip_$dt" c60.urdf 0.0207 "$dt" unconverged --command "$probe"
  run "handle_$dt" c60.urdf 0.040 "$dt" unconverged --command "$handle"
  run "bench_$dt" c60_bench.urdf 0.054 "$dt" unconverged --command "$C60_TABLE"
done
run trip_sample c60.urdf 0.0207 1e-5 250 --command "$probe"
for f in "$out"/dump/*/*.txt; do
  tag=$(basename "$(dirname "$f")")
  name="c60_${tag}_$(basename "$f" .txt)"
  "$bin/nscd_fclib" --from-nscd "$f" "$out/problems/$name.hdf5" --title "$name" \
    --description "C-60 (urdf/$( [[ $tag == bench* ]] && echo c60_bench || echo c60).urdf), nscd_run --dump-problems" \
    > /dev/null || echo "skipped $(basename "$f")" >&2
done
# Solves that builds of this engine once left unconverged (kept: the engine now
# converges on them, so the runs above no longer dump them).
cp "$repo"/tools/fclib/c60_hard/*.hdf5 "$out/problems/"
n=$(ls "$out"/problems/*.hdf5 | wc -l)
echo "$n problems in $out/problems"
first=1
for p in "$out"/problems/*.hdf5; do
  "$bin/nscd_fclib" --tol 1e-8,1e-10 --max-iter 10000 --min-ms 5 --csv "$out/one.csv" "$p" \
    >> "$out/fclib.txt" 2>> "$out/siconos_stderr.log" || echo "$(basename "$p"): nscd_fclib exited $?" >&2
  if [ -f "$out/one.csv" ]; then
    if [ $first = 1 ]; then cat "$out/one.csv" > "$out/fclib.csv"; first=0; else tail -n +2 "$out/one.csv" >> "$out/fclib.csv"; fi
    rm -f "$out/one.csv"
  fi
done
/usr/bin/python3 "$repo/scripts/analysis/fclib_table.py" "$out/fclib.csv" --made-by "$made_by" \
  --started "$started" --load-start "$load_start" > "$out/fclib.md"
echo "written: $out/fclib.csv $out/fclib.md"
