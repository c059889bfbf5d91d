#!/usr/bin/env bash
# The trip of the main C-60 model (urdf/c60.urdf) and of the authors' model
# (urdf/c60_authors.urdf) side by side: probe at 0.2 m/s from 0.7 ms, 20.7 ms, CSV every 2
# steps. Prints the table of docs/c60.md "Trip: main model vs the authors' model" and
# writes the CSVs, a JSON and the plots (c60_trip_*.png) into the output folder.
#   scripts/c60_trip_compare.sh [OUTDIR (default out/)] [extra nscd_run args...]
#   C60_FIGURE=docs/images/c60_trip_compare.png scripts/c60_trip_compare.sh   (the docs' figure)
#   C60_EVERY=1 scripts/c60_trip_compare.sh out/dt1e-6 --dt 1e-6   (the recommended step, every step in the CSV)
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
outdir=${1:-$C60_OUT}
shift || true
mkdir -p "$outdir"
for m in c60 c60_authors; do
  "$NSCD_RUN" "$C60_REPO/urdf/$m.urdf" --duration 0.0207 --command "$C60_PROBE" \
    --csv "$outdir/${m}_trip_compare.csv" --every "${C60_EVERY:-2}" --quiet "$@" | tee "$outdir/${m}_trip_compare.run.json"
done
fig=()
[ -n "${C60_FIGURE:-}" ] && fig=(--figure "$C60_FIGURE")
$PY "$C60_REPO/scripts/analysis/c60_trip_compare.py" "$outdir" "main=$outdir/c60_trip_compare.csv" \
  "authors=$outdir/c60_authors_trip_compare.csv" --json "$outdir/c60_trip_compare.json" "${fig[@]}"
