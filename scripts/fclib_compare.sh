#!/usr/bin/env bash
# FCLib problems solved by nscd_sim's FrictionContactSolver and by Siconos's fc3d
# solvers, at tolerances 1e-4, 1e-8, 1e-10 (Siconos's error measure).
#   scripts/fclib_compare.sh [OUT_DIR] [--regenerate] [extra nscd_fclib options]
# Problems: tools/fclib/problems/*.hdf5 (committed); with --regenerate they are
# dumped again from the Siconos scenes of scripts/analysis/fclib_generate.py (needs
# python3-siconos) into OUT_DIR/problems and converted with nscd_fclib --convert.
# Writes OUT_DIR/fclib.csv and OUT_DIR/fclib.md; default OUT_DIR: build/fclib_compare.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
made_by="${OPENBLAS_NUM_THREADS:+OPENBLAS_NUM_THREADS=$OPENBLAS_NUM_THREADS }scripts/fclib_compare.sh $*" started=$(date +%s) load_start=$(cut -d' ' -f1 /proc/loadavg)
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
out=${1:-$repo/build/fclib_compare}
shift || true
exe=$ws/devel/lib/nscd_sim/nscd_fclib
if [ ! -x "$exe" ]; then
  echo "no $exe: run scripts/install_siconos.sh, then scripts/build.sh" >&2
  exit 1
fi
mkdir -p "$out"
problems=("$repo"/tools/fclib/problems/*.hdf5)
if [ "${1:-}" = "--regenerate" ]; then
  shift
  rm -rf "$out/problems"
  /usr/bin/python3 "$repo/scripts/analysis/fclib_generate.py" "$out/problems" 2>&1 | grep -v 'memory leak' || true
  for f in "$out"/problems/*.dat; do
    name=$(basename "$f" .dat)
    "$exe" --convert "$f" "$out/problems/$name.hdf5" --title "$name" \
      --description "scripts/analysis/fclib_generate.py (python3-siconos)" > /dev/null
  done
  problems=("$out"/problems/*.hdf5)
fi
# Siconos's Newton solvers report failed LU factorisations on stderr: keep them apart.
"$exe" --csv "$out/fclib.csv" "$@" "${problems[@]}" 2> "$out/siconos_stderr.log" | tee "$out/fclib.txt" || true
/usr/bin/python3 "$repo/scripts/analysis/fclib_table.py" "$out/fclib.csv" --made-by "$made_by" \
  --started "$started" --load-start "$load_start" > "$out/fclib.md"
echo "written: $out/fclib.csv $out/fclib.md"
