# Sourced by the ROS test scripts that start their own master (ros_tools_smoke.sh,
# rosbag_roundtrip.sh): the built workspace's environment, the output folder
# OUT_DIR (the script's first argument, default a fresh temporary folder) and a
# master URI on a free local port, so that tests never meet another master.
# Sets: here repo out ws ROS_HOME ROS_MASTER_URI ROS_IP.
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
here=$(cd "$(dirname "${BASH_SOURCE[1]}")" && pwd)
repo=$(cd "$here/../.." && pwd)
out=${1:-$(mktemp -d)}
mkdir -p "$out"
ws=${NSCD_WS:-$repo/.build/ws}
[ -f "$ws/devel/setup.bash" ] || { echo "FAIL: no workspace $ws (run scripts/build.sh)"; exit 1; }
set +u; source "$ws/devel/setup.bash"; set -u
export ROS_HOME=$out/ros_home
port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1
unset ROS_HOSTNAME
