#!/usr/bin/env bash
# C-60 at rest in ON: 100 ms with no input. The joints take up their clearances in the
# first ~4 ms (the CAD pose has every joint centred); the script reports the drift and the
# contact forces over the second half (out/c60_rest.json).
#   scripts/c60_rest.sh [SCENE.urdf] [extra nscd_run args...]
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
scene=${1:-$C60_REPO/urdf/c60.urdf}
shift || true
tag=${C60_TAG:-c60_rest}
"$NSCD_RUN" "$scene" --duration 0.1 --csv "$C60_OUT/$tag.csv" --every 10 --quiet "$@" | tee "$C60_OUT/$tag.run.json"
$PY "$C60_REPO/scripts/analysis/c60_plot.py" rest "$C60_OUT/$tag.csv" --json "$C60_OUT/$tag.json"
