#!/usr/bin/env bash
# The rosbag round trip of docs/node.md on the C-60 trip: the node (config/c60_trip.yaml,
# started paused) is stepped to 9.5 ms of sim time (past the latch release and the opening) while
# `rosbag record` records what RViz shows; the node stops; launch/c60_playback.launch
# (rviz:=false) plays the bag, and rosbag_roundtrip.py checks that the key figures,
# status texts, contact markers (with the event label), /tf, /joint_states and /clock
# arrive, equal to the recorded ones. Own master on a free port; stops what it starts.
# Usage: rosbag_roundtrip.sh [OUT_DIR]   (NSCD_WS: the built workspace)
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/private_master_env.sh" "$@"
bag=$out/c60_trip.bag
rm -f "$bag" "$bag.active"

launch_pid="" record_pid=""
stop() {  # pid: SIGINT, 10 s, then SIGKILL to its process group
  local p=$1
  [ -n "$p" ] && kill -0 "$p" 2>/dev/null || return 0
  kill -INT "$p" 2>/dev/null
  for _ in $(seq 100); do kill -0 "$p" 2>/dev/null || return 0; sleep 0.1; done
  kill -KILL -- "-$p" 2>/dev/null || kill -KILL "$p" 2>/dev/null
}
cleanup() { stop "$record_pid"; stop "$launch_pid"; }
trap cleanup EXIT

# 1. The node, paused, and the recorder.
setsid roslaunch -p "$port" nscd_sim c60.launch rviz:=false \
  config:="$repo/config/c60_trip.yaml" >"$out/node.log" 2>&1 &
launch_pid=$!
topics="/tf /joint_states /nscd_sim_node/key_figures /nscd_sim_node/contact_markers /nscd_sim_node/status /nscd_sim_node/contacts /diagnostics"
for _ in $(seq 300); do rosservice list 2>/dev/null | grep -q /nscd_sim_node/step && break; sleep 0.1; done
setsid rosbag record -O "$bag" $topics >"$out/record.log" 2>&1 &
record_pid=$!
# The recorder subscribed to every topic (the node publishes markers and key
# figures only to subscribers).
for _ in $(seq 200); do
  n=0
  for t in /nscd_sim_node/key_figures /nscd_sim_node/contact_markers /nscd_sim_node/status; do
    rostopic info "$t" 2>/dev/null | sed -n '/Subscribers:/,$p' | grep -q record && n=$((n + 1))
  done
  [ "$n" -eq 3 ] && break
  sleep 0.1
done
[ "$n" -eq 3 ] || { echo "FAIL: rosbag record did not subscribe"; cat "$out/record.log"; exit 1; }
/usr/bin/python3 "$here/rosbag_roundtrip.py" drive 0.0095 || { echo "FAIL: driving the node"; tail "$out/node.log"; exit 1; }
sleep 1
stop "$record_pid"; record_pid=""
stop "$launch_pid"; launch_pid=""
[ -f "$bag" ] || { echo "FAIL: no bag $bag"; cat "$out/record.log"; exit 1; }
rosbag info "$bag" >"$out/bag_info.txt" || { echo "FAIL: rosbag info"; exit 1; }

# 2. Played back without the node, at 1/100 of real time (the 9.5 ms last 1 s). The
# checker must be subscribed before the play starts: under load (a 2-core machine
# building beside it) its Python start and the bag read took more than 2 s.
setsid roslaunch -p "$port" nscd_sim c60_playback.launch bag:="$bag" rviz:=false rate:=0.01 \
  start_delay:=8 >"$out/playback.log" 2>&1 &
launch_pid=$!
for _ in $(seq 150); do rosparam get /use_sim_time >/dev/null 2>&1 && break; sleep 0.1; done
rosparam get /use_sim_time >/dev/null 2>&1 || { echo "FAIL: c60_playback.launch did not start"; tail -n 20 "$out/playback.log"; exit 1; }
if timeout 60 /usr/bin/python3 "$here/rosbag_roundtrip.py" check "$bag"; then
  grep -q "nscd_sim_node" <(rosnode list 2>/dev/null) && { echo "FAIL: the node runs during playback"; exit 1; }
  echo "PASS"
  exit 0
fi
echo "--- playback log"; tail -n 20 "$out/playback.log"
exit 1
