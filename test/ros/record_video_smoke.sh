#!/usr/bin/env bash
# Smoke test of scripts/record_video.sh: 1 s of video of a small scene, an MP4 of
# that length and a PNG are written, and no process it started is left running.
# Usage: record_video_smoke.sh OUT_DIR   (NSCD_WS: the built workspace)
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=${1:-$(mktemp -d)}
mkdir -p "$out"
rm -f "$out/smoke.mp4" "$out/smoke.png"

log=$(bash "$repo/scripts/record_video.sh" -s "$repo/test/ros/actuated_pendulum.urdf" -d 1 \
  --fps 10 --size 640x360 -o "$out/smoke.mp4" 2>&1) || { echo "$log"; echo "FAIL: record_video.sh exited non-zero"; exit 1; }
echo "$log"
fail=0
[ -s "$out/smoke.mp4" ] || { echo "FAIL: no MP4"; fail=1; }
[ -s "$out/smoke.png" ] || { echo "FAIL: no PNG"; fail=1; }
if [ -s "$out/smoke.mp4" ]; then
  dur=$(ffprobe -v error -show_entries format=duration -of csv=p=0 "$out/smoke.mp4")
  size=$(ffprobe -v error -select_streams v:0 -show_entries stream=width,height -of csv=p=0 "$out/smoke.mp4")
  awk -v d="$dur" 'BEGIN { exit !(d > 0.8 && d < 1.3) }' || { echo "FAIL: duration $dur s, expected 1"; fail=1; }
  [ "$size" = "640,360" ] || { echo "FAIL: size $size, expected 640,360"; fail=1; }
fi
# Leftovers: anything still running that mentions the script's master port or temp dir.
port=$(echo "$log" | sed -n 's/.*ROS master port \([0-9]*\).*/\1/p')
tmp=$(echo "$log" | sed -n 's/.*temporary files in \([^ ]*\).*/\1/p')
[ -n "$port" ] && [ -n "$tmp" ] || { echo "FAIL: no port/temp dir in the log"; fail=1; }
if [ -n "$port" ] && [ -n "$tmp" ]; then
  left=$(ps -eo pid=,args= | grep -E -- "$tmp|:$port|-p $port" | grep -v -E "grep|record_video_smoke" || true)
  [ -z "$left" ] || { echo "FAIL: left running:"; echo "$left"; fail=1; }
  [ ! -e "$tmp" ] || { echo "FAIL: $tmp not removed"; fail=1; }
fi
display=$(echo "$log" | sed -n 's/.*display :\([0-9]*\),.*/\1/p')
[ -z "$display" ] || [ ! -e "/tmp/.X11-unix/X$display" ] || { echo "FAIL: X server :$display still running"; fail=1; }
[ "$fail" -eq 0 ] && echo "record_video smoke test: OK"
exit "$fail"
