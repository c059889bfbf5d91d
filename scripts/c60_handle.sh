#!/usr/bin/env bash
# C-60 handle: the handle servo (position actuator "handle" on J1) is commanded from ON
# (0 rad) towards OFF (+1.2 rad, anticlockwise) and back. Writes out/c60_handle.csv and
# docs/c60_handle.png. In the node the same is `rostopic pub /nscd_sim_node/handle/command
# std_msgs/Float64 1.2`.
#   scripts/c60_handle.sh [SCENE.urdf] [extra nscd_run args...]
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
scene=${1:-$C60_REPO/urdf/c60.urdf}
shift || true
tag=${C60_TAG:-c60_handle}
png=${C60_PNG-$C60_DOCS/c60_handle.png}
# settle 4 ms | to +1.2 rad in 10 ms | hold 6 ms | back to 0 in 10 ms | hold 10 ms
cmd="handle=0:0,0.004:0,0.014:1.2,0.020:1.2,0.030:0,0.040:0"
"$NSCD_RUN" "$scene" --duration 0.040 --command "$cmd" --csv "$C60_OUT/$tag.csv" --every 5 --quiet "$@" \
  | tee "$C60_OUT/$tag.run.json"
$PY "$C60_REPO/scripts/analysis/c60_plot.py" handle "$C60_OUT/$tag.csv" $png --json "$C60_OUT/$tag.json"
