#!/usr/bin/env bash
# Records a scene off-screen: nscd_sim_node + RViz under Xvfb, grabbed by ffmpeg
# into an MP4, plus one PNG snapshot. Needs no display and no running ROS master
# (it starts its own on a free port). Every process it starts is stopped on exit.
#
#   scripts/record_video.sh [options]
#     -s, --scene FILE      scene URDF (default: urdf/fourbar.urdf of the package)
#     -d, --duration S      seconds of video (default 5)
#     -o, --output FILE     MP4 to write (default: out/<scene>.mp4)
#     -p, --png FILE        PNG snapshot (default: the MP4 path with .png)
#         --snapshot-at S   when to take the snapshot, seconds into the video
#                           (default: half the duration)
#     -c, --config FILE     node parameters YAML (default: config/nscd.yaml)
#     -r, --rviz FILE       RViz config (default: config/nscd.rviz)
#         --rtf X           real-time factor of the simulation (default: the config's)
#         --size WxH        video size (default 1280x720)
#         --fps N           frames per second (default 15)
#         --panels          keep RViz's side panels (default: 3D view and Time panel only)
#         --keep-panel CLASS  keep this panel too (e.g. nscd_sim/KeyFigures); repeatable
#         --stills T1,T2,...  no video: step the paused simulation (~step, 20 steps
#                           at a time, so plots fill in) to each sim time T (s) and
#                           write a PNG of the screen there: <output without .mp4>_<T in ms>ms.png
#         --launch FILE     launch file of the package instead of sim.launch (it takes
#                           the same arguments: scene, config, rviz, rviz_config), e.g. c60.launch
#         --drive PROGRAM   no video: once RViz is up and the node paused, run PROGRAM
#                           OUTPUT_PREFIX WxH DISPLAY (it drives the scene and grabs the
#                           screen itself; scripts/c60_drag.py) and exit with its status
#     -h, --help
# The package must be built: with NSCD_WS (default <repo>/.build/ws, what
# scripts/build.sh makes) or an environment where `rospack find nscd_sim` works.
# The simulation starts paused and is resumed as ffmpeg starts, so the video
# begins at sim time 0 (the first ~second, while the resume call starts up,
# shows the initial configuration).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)

scene="" duration=5 output="" png="" snapshot_at="" config="" rviz="" rtf=""
size=1280x720 fps=15 panels=0 keep="" stills="" launch=sim.launch drive=""
usage() { sed -n '2,33p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }
while [ $# -gt 0 ]; do
  case "$1" in
    -s|--scene) scene=$2; shift 2 ;;
    -d|--duration) duration=$2; shift 2 ;;
    -o|--output) output=$2; shift 2 ;;
    -p|--png) png=$2; shift 2 ;;
    --snapshot-at) snapshot_at=$2; shift 2 ;;
    -c|--config) config=$2; shift 2 ;;
    -r|--rviz) rviz=$2; shift 2 ;;
    --rtf) rtf=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --fps) fps=$2; shift 2 ;;
    --panels) panels=1; shift ;;
    --keep-panel) keep="$keep|$2"; shift 2 ;;
    --stills) stills=$2; shift 2 ;;
    --launch) launch=$2; shift 2 ;;
    --drive) drive=$(realpath "$2"); shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) echo "record_video.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
case "$size" in *x*) width=${size%x*}; height=${size#*x} ;; *) echo "bad --size '$size'" >&2; exit 2 ;; esac
for tool in Xvfb ffmpeg xwininfo roslaunch rosservice; do
  command -v "$tool" >/dev/null || { echo "record_video.sh: '$tool' not found" >&2; exit 2; }
done

# ROS environment: the catkin workspace if there is one, else the caller's.
ws=${NSCD_WS:-$repo/.build/ws}
if [ -f "$ws/devel/setup.bash" ]; then
  set +u; source "$ws/devel/setup.bash"; set -u
fi
pkg=$(rospack find nscd_sim 2>/dev/null || true)
[ -n "$pkg" ] || { echo "record_video.sh: package nscd_sim not found; build it (scripts/build.sh) or set NSCD_WS" >&2; exit 2; }

scene=$(realpath "${scene:-$pkg/urdf/fourbar.urdf}")
config=$(realpath "${config:-$pkg/config/nscd.yaml}")
rviz=$(realpath "${rviz:-$pkg/config/nscd.rviz}")
[ -f "$scene" ] || { echo "record_video.sh: no scene file $scene" >&2; exit 2; }
name=$(basename "$scene" .urdf)
output=${output:-$repo/out/$name.mp4}
png=${png:-${output%.*}.png}
snapshot_at=${snapshot_at:-$(awk "BEGIN{print $duration/2}")}
mkdir -p "$(dirname "$output")" "$(dirname "$png")"
output=$(realpath "$output"); png=$(realpath "$png")

tmp=$(mktemp -d /tmp/nscd_record.XXXXXX)
export ROS_HOME=${ROS_HOME:-$tmp/ros_home}
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port
export ROS_IP=127.0.0.1
unset ROS_HOSTNAME

xvfb_pid="" launch_pid="" ffmpeg_pid="" snap_pid="" launch_tree=""
descendants() {  # every process below $1 (roslaunch puts each node in its own session)
  local p
  for p in $(ps -o pid= --ppid "$1" 2>/dev/null); do echo "$p"; descendants "$p"; done
}
stop() {  # pid, signal, seconds to wait
  local pid=$1 sig=$2 wait=$3 i
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill "-$sig" "$pid" 2>/dev/null || true
  for ((i = 0; i < wait * 10; i++)); do kill -0 "$pid" 2>/dev/null || return 0; sleep 0.1; done
  kill -KILL -- "-$pid" 2>/dev/null || kill -KILL "$pid" 2>/dev/null || true
}
cleanup() {
  local rc=$? p
  stop "$snap_pid" INT 2
  stop "$ffmpeg_pid" INT 5
  if [ -n "$launch_pid" ]; then
    launch_tree="$launch_tree $(descendants "$launch_pid")"
    stop "$launch_pid" INT 15   # roslaunch stops its nodes, rviz and its master
    for p in $launch_tree; do kill -0 "$p" 2>/dev/null && kill -KILL "$p" 2>/dev/null; done
  fi
  stop "$xvfb_pid" TERM 5
  rm -rf "$tmp"
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

t_start=$(date +%s.%N)
# 1. X server on a free display.
setsid Xvfb -displayfd 3 -screen 0 "${width}x${height}x24" -nolisten tcp 3>"$tmp/display" \
  >"$tmp/xvfb.log" 2>&1 &
xvfb_pid=$!
for _ in $(seq 100); do [ -s "$tmp/display" ] && break; sleep 0.1; done
[ -s "$tmp/display" ] || { echo "record_video.sh: Xvfb did not start" >&2; cat "$tmp/xvfb.log" >&2; exit 1; }
export DISPLAY=:$(head -n1 "$tmp/display")
echo "record_video.sh: display $DISPLAY, ROS master port $port, temporary files in $tmp" >&2

# 2. The node (paused) and RViz, with the RViz window filling the screen.
cp "$config" "$tmp/node.yaml"
printf '\nstart_paused: true\n' >> "$tmp/node.yaml"
[ -z "$rtf" ] || printf 'real_time_factor: %s\n' "$rtf" >> "$tmp/node.yaml"
# The RViz window fills the screen; without --panels only the Time panel (it
# shows sim time) is kept, so the 3D view takes the rest.
awk -v only_time="$((1 - panels))" -v w="$width" -v h="$height" -v keep="${keep#|}" '
  /^  - Class: / { c = $0; sub(/^  - Class: /, "", c)
                   skip = (only_time && c != "rviz/Time" && !(keep != "" && c ~ ("^(" keep ")$"))) }
  /^[^ ]/ { skip = 0 }
  /^  Height: / { print "  Height: " h; next }
  /^  Width: / { print "  Width: " w; next }
  !skip' "$rviz" > "$tmp/record.rviz"
setsid roslaunch -p "$port" nscd_sim "$launch" scene:="$scene" config:="$tmp/node.yaml" \
  rviz_config:="$tmp/record.rviz" rviz:=true >"$tmp/launch.log" 2>&1 &
launch_pid=$!

for _ in $(seq 600); do
  xwininfo -root -tree 2>/dev/null | grep -qi 'rviz' && break
  kill -0 "$launch_pid" 2>/dev/null || { echo "record_video.sh: roslaunch exited:" >&2; tail -n 20 "$tmp/launch.log" >&2; exit 1; }
  sleep 0.1
done
xwininfo -root -tree | grep -qi 'rviz' || { echo "record_video.sh: no RViz window after 60 s" >&2; tail -n 20 "$tmp/launch.log" >&2; exit 1; }
rosservice call --wait /nscd_sim_node/pause "data: true" >/dev/null
sleep 2  # RViz loads the robot model and receives the first transforms
launch_tree=$(descendants "$launch_pid")

# 3a. A driver program does the rest.
if [ -n "$drive" ]; then
  "$drive" "${output%.*}" "${width}x${height}" "$DISPLAY"
  exit $?
fi

# 3b. Stills: step to each sim time, let RViz draw, grab the screen.
if [ -n "$stills" ]; then
  /usr/bin/python3 - "$stills" "${output%.*}" "${width}x${height}" "$DISPLAY" <<'PY'
import subprocess, sys, time
import rospy
from nscd_sim.srv import Step
times = [float(x) for x in sys.argv[1].split(',') if x.strip()]
prefix, size, display = sys.argv[2:5]
rospy.init_node('record_stills', anonymous=True, disable_signals=True)
rospy.wait_for_service('/nscd_sim_node/step', 30)
step = rospy.ServiceProxy('/nscd_sim_node/step', Step)
t = 0.0
for target in times:
    while t < target - 1e-9:
        r = step(20)
        if not r.success:
            sys.exit('record_video.sh: ~step failed: ' + r.message)
        t = r.sim_time
        time.sleep(0.05)  # one publication per call: the panel's plot gets every point
    time.sleep(3.0)       # RViz draws the last state
    png = '%s_%gms.png' % (prefix, round(1e3 * target, 3))
    subprocess.run(['ffmpeg', '-nostdin', '-y', '-loglevel', 'error', '-f', 'x11grab', '-draw_mouse', '0',
                    '-video_size', size, '-i', display, '-frames:v', '1', png], check=True)
    print('record_video.sh: %s at sim time %.6f s' % (png, t), file=sys.stderr)
PY
  exit 0
fi

# 3. Record; the simulation runs from when the grab starts.
t_rec=$(date +%s.%N)
setsid ffmpeg -nostdin -y -loglevel error -f x11grab -draw_mouse 0 -video_size "${width}x${height}" \
  -framerate "$fps" -i "$DISPLAY" -t "$duration" -c:v libx264 -preset veryfast -pix_fmt yuv420p \
  "$output" >"$tmp/ffmpeg.log" 2>&1 &
ffmpeg_pid=$!
setsid bash -c 'sleep "$1" && exec ffmpeg -nostdin -y -loglevel error -f x11grab -draw_mouse 0 \
  -video_size "$2" -i "$3" -frames:v 1 "$4"' snapshot "$snapshot_at" "${width}x${height}" \
  "$DISPLAY" "$png" >"$tmp/snapshot.log" 2>&1 &
snap_pid=$!
rosservice call /nscd_sim_node/pause "data: false" >/dev/null
wait "$ffmpeg_pid" || { echo "record_video.sh: ffmpeg failed:" >&2; cat "$tmp/ffmpeg.log" >&2; exit 1; }
ffmpeg_pid=""
wait "$snap_pid" || echo "record_video.sh: snapshot failed: $(cat "$tmp/snapshot.log")" >&2
snap_pid=""
t_end=$(date +%s.%N)

grep -E 'rtf|steps' "$tmp/launch.log" | tail -n 2 >&2 || true
awk -v a="$t_start" -v b="$t_rec" -v c="$t_end" -v d="$duration" -v o="$output" -v p="$png" \
  'BEGIN { printf "record_video.sh: %s (%g s of video) and %s in %.1f s (%.1f s start-up, %.1f s recording)\n", o, d, p, c - a, b - a, c - b }'
