#!/usr/bin/env bash
# The ROS command-line tools the README and docs/node.md tell users to run, against
# a running nscd_sim_node: each must work on a machine set up by scripts/deps.sh
# (they load Python message classes of every type they touch, and rosrun must find
# exactly one executable of each name). Starts its own master on a free port and
# stops everything it started.
# Usage: ros_tools_smoke.sh OUT_DIR   (NSCD_WS: the built workspace)
set -uo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/private_master_env.sh" "$@"

fail=0
check() {  # NAME COMMAND...: runs it (20 s at most), fails on non-zero exit or a warning we know
  local name=$1 log=$out/$1.log
  shift
  if ! timeout 20 "$@" >"$log" 2>&1; then
    echo "FAIL: $name: '$*' exited non-zero:"; tail -n 5 "$log"; fail=1; return 1
  fi
  if grep -qE "File system loop|Unable to load type|Cannot load message class|non-unique" "$log"; then
    echo "FAIL: $name: '$*' printed:"; grep -E "loop|Unable|Cannot|non-unique" "$log" | head -3; fail=1; return 1
  fi
  echo "ok: $name"
}

master_pid="" node_pid=""
cleanup() {
  for p in $node_pid $master_pid; do
    kill -INT "$p" 2>/dev/null
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL "$p" 2>/dev/null
  done
}
trap cleanup EXIT

check rosrun_nscd_run rosrun nscd_sim nscd_run --help
setsid rosmaster --core -p "$port" >"$out/master.log" 2>&1 &
master_pid=$!
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done
setsid rosrun nscd_sim nscd_sim_node _scene:="$here/actuated_pendulum.urdf" _start_paused:=true \
  >"$out/node.log" 2>&1 &
node_pid=$!
check wait_for_step_service rosservice call --wait /nscd_sim_node/step "count: 10"
grep -q "File system loop" "$out/node.log" && { echo "FAIL: rosrun nscd_sim_node: File system loop"; fail=1; }
check rosservice_pause rosservice call /nscd_sim_node/pause "data: false"
check rosservice_reset rosservice call /nscd_sim_node/reset
check rostopic_echo_tf rostopic echo -n 1 /tf
check rostopic_echo_diagnostics rostopic echo -n 1 /diagnostics
check rostopic_echo_contacts rostopic echo -n 1 /nscd_sim_node/contacts
check rostopic_echo_markers rostopic echo -n 1 /nscd_sim_node/contact_markers
check rostopic_echo_key_figures rostopic echo -n 1 /nscd_sim_node/key_figures
check rostopic_echo_joint_states rostopic echo -n 1 /joint_states
check rostopic_pub rostopic pub -1 /nscd_sim_node/hinge_motor/command std_msgs/Float64 "data: 0.3"
check rosmsg_show rosmsg show nscd_sim/ContactArray
check rosbag_record rosbag record -O "$out/smoke.bag" --duration=2 /tf /nscd_sim_node/contacts /diagnostics
check rosbag_info rosbag info "$out/smoke.bag"
if [ -s "$out/rosbag_info.log" ]; then
  for t in /tf /nscd_sim_node/contacts; do
    grep -q "$t" "$out/rosbag_info.log" || { echo "FAIL: the bag holds no $t"; fail=1; }
  done
fi
[ "$fail" -eq 0 ] && echo "ROS tools smoke test: OK"
exit "$fail"
