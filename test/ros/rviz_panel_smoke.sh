#!/usr/bin/env bash
# Smoke test of the RViz panel plugin nscd_sim/KeyFigures: RViz runs under Xvfb
# (xvfb-run -a) for ~15 s with config/c60.rviz (which holds the panel), against a
# ROS master of its own on a free port (RViz needs one; the node is not started).
# Fails if RViz's output has a plugin-load error ("PluginlibFactory", "Failed to
# load", "could not be loaded"), a crash, or RViz exits early; passes if, in
# addition, the panel subscribed to /nscd_sim_node/key_figures (the master lists an
# RViz subscriber), which only an initialized panel does.
# Usage: rviz_panel_smoke.sh [OUT_DIR] [RVIZ_CONFIG]   (NSCD_WS: the built workspace)
set -uo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=${1:-$(mktemp -d)}
config=${2:-$repo/config/c60.rviz}
mkdir -p "$out"
ws=${NSCD_WS:-$repo/.build/ws}
[ -f "$ws/devel/setup.bash" ] || { echo "FAIL: no workspace $ws (run scripts/build.sh)"; exit 1; }
set +u; source "$ws/devel/setup.bash"; set -u
for tool in xvfb-run rviz rosmaster timeout; do
  command -v "$tool" >/dev/null || { echo "FAIL: '$tool' not found"; exit 1; }
done

tmp=$(mktemp -d /tmp/nscd_rviz_panel.XXXXXX)
export ROS_HOME=$tmp/ros_home HOME=$tmp/home
mkdir -p "$ROS_HOME" "$HOME"
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1
unset ROS_HOSTNAME
master_pid="" rviz_pid=""
cleanup() {
  local p
  for p in $rviz_pid $master_pid; do
    kill -0 "$p" 2>/dev/null || continue
    kill -TERM -- "-$p" 2>/dev/null || kill -TERM "$p" 2>/dev/null
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -KILL -- "-$p" 2>/dev/null || true
  done
  rm -rf "$tmp"
}
trap cleanup EXIT

setsid rosmaster --core -p "$port" >"$out/master.log" 2>&1 &
master_pid=$!
# The master answers (up to 15 s on a loaded machine).
/usr/bin/python3 - "$ROS_MASTER_URI" <<'PY' || { echo "FAIL: no ROS master"; cat "$out/master.log"; exit 1; }
import sys, time, xmlrpc.client
m = xmlrpc.client.ServerProxy(sys.argv[1])
for _ in range(150):
    try:
        m.getSystemState("/smoke"); sys.exit(0)
    except Exception:
        time.sleep(0.1)
sys.exit(1)
PY

# RViz for 15 s; timeout's exit status 124 means it was still running then.
# (The status is written inside xvfb-run: its own can be that of its clean-up. The
# X authority file is ours (-f): xvfb-run then has no temporary folder to remove, a
# step whose failure made it exit without stopping Xvfb.)
rm -f "$out/rviz.rc"
setsid xvfb-run -a -f "$tmp/xauthority" -s "-screen 0 1280x720x24" bash -c 'timeout -k 5 -s INT 15 rviz -d "$1"; \
  echo $? >"$2"' rviz "$config" "$out/rviz.rc" >"$out/rviz.log" 2>&1 &
rviz_pid=$!
# The panel's subscription, seen by the master, while RViz runs.
/usr/bin/python3 - "$ROS_MASTER_URI" >"$out/subscribers.txt" <<'PY'
import sys, time, xmlrpc.client
m = xmlrpc.client.ServerProxy(sys.argv[1])
for _ in range(140):
    try:
        _, _, (pubs, subs, srvs) = m.getSystemState("/smoke")
        for topic, nodes in subs:
            if topic == "/nscd_sim_node/key_figures":
                print(" ".join(nodes)); sys.exit(0)
    except Exception:
        pass
    time.sleep(0.1)
PY
wait "$rviz_pid"
rviz_pid=""
rc=$(cat "$out/rviz.rc" 2>/dev/null || echo none)
cat "$out/rviz.log"
fail=0
if grep -nE 'PluginlibFactory|Failed to load|could not be loaded|Segmentation fault|core dumped|terminate called|Aborted' "$out/rviz.log"; then
  echo "FAIL: RViz reported the lines above"; fail=1
fi
[ "$rc" = 124 ] || { echo "FAIL: RViz ended early (exit status $rc, expected 124 from timeout)"; fail=1; }
grep -q '/rviz' "$out/subscribers.txt" ||
  { echo "FAIL: no RViz subscriber on /nscd_sim_node/key_figures (the panel did not start)"; fail=1; }
# No X server left: xvfb-run has stopped its Xvfb (the one using our authority file).
xvfb_left() { ps -eo args= | grep -F -- "$tmp/xauthority" | grep -q '^Xvfb'; }
for _ in $(seq 50); do xvfb_left || break; sleep 0.1; done
if xvfb_left; then
  echo "FAIL: Xvfb still running after xvfb-run ended"; fail=1
fi
[ "$fail" -eq 0 ] && echo "rviz panel smoke test: OK (subscriber $(cat "$out/subscribers.txt"))"
exit "$fail"
