#!/usr/bin/env bash
# C-60 trip: from ON the probe moves at 0.2 m/s from t = 0.7 ms, pushes the tripping bar,
# the latch (C4) releases and the contacts open. Writes out/c60_trip.csv, docs/c60_trip.png.
#   scripts/c60_trip.sh [SCENE.urdf] [extra nscd_run args...]
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
scene=${1:-$C60_REPO/urdf/c60.urdf}
shift || true
tag=${C60_TAG:-c60_trip}
png=${C60_PNG-$C60_DOCS/c60_trip.png}
"$NSCD_RUN" "$scene" --duration 0.0207 --command "$C60_PROBE" --csv "$C60_OUT/$tag.csv" --every 2 --quiet "$@" \
  | tee "$C60_OUT/$tag.run.json"
$PY "$C60_REPO/scripts/analysis/c60_plot.py" trip "$C60_OUT/$tag.csv" $png --json "$C60_OUT/$tag.json"
