#!/usr/bin/env bash
# What the springs' load model changes (docs/c60.md, "What the loads change"): the trip at
# dt 1e-6 (every step in the CSV) and the paper's bench (scripts/c60_bench.sh's protocol,
# the scenes' dt) of the main model (urdf/c60.urdf, c60_bench.urdf), the authors' model
# with the published loads (urdf/c60_authors.urdf, c60_authors_bench.urdf) and the same
# with its springs as moment pairs and a line force (c60_scene.py --spring-pairs, written
# into the output folder). Prints the table, with the command, the date and the commit.
#   scripts/c60_loads_compare.sh [OUTDIR (default out/loads_compare)]
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
outdir=${1:-$C60_OUT/loads_compare}
mkdir -p "$outdir"
$PY "$C60_REPO/scripts/c60_model/c60_scene.py" --variant authors --spring-pairs --out "$outdir/c60_authors_pairs.urdf"
$PY "$C60_REPO/scripts/c60_model/c60_scene.py" --variant authors --spring-pairs --bench \
  --out "$outdir/c60_authors_pairs_bench.urdf"
labels=(main authors authors_pairs)
trips=("$C60_REPO/urdf/c60.urdf" "$C60_REPO/urdf/c60_authors.urdf" "$outdir/c60_authors_pairs.urdf")
benches=("$C60_REPO/urdf/c60_bench.urdf" "$C60_REPO/urdf/c60_authors_bench.urdf" "$outdir/c60_authors_pairs_bench.urdf")
args=()
for i in 0 1 2; do
  l=${labels[$i]}
  "$NSCD_RUN" "${trips[$i]}" --duration 0.0207 --command "$C60_PROBE" --dt 1e-6 --every 1 --quiet \
    --csv "$outdir/${l}_trip.csv" > "$outdir/${l}_trip.run.json"
  "$NSCD_RUN" "${benches[$i]}" --duration 0.054 --command "$C60_TABLE" --every 5 --quiet \
    --csv "$outdir/${l}_bench.csv" > "$outdir/${l}_bench.run.json"
  args+=(--trip "$l=$outdir/${l}_trip.csv" --bench "$l=$outdir/${l}_bench.csv")
done
commit=$(git -C "$C60_REPO" rev-parse --short HEAD 2>/dev/null || echo unknown)
git -C "$C60_REPO" diff --quiet HEAD -- 2>/dev/null || commit="$commit+changes"
$PY "$C60_REPO/scripts/analysis/c60_loads_compare.py" "${args[@]}" --json "$outdir/c60_loads_compare.json" \
  --command "scripts/c60_loads_compare.sh" --date "$(date -u +%Y-%m-%d)" --commit "$commit"
