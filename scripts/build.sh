#!/usr/bin/env bash
# Builds nscd_sim (Release) as a catkin package configured directly by CMake (catkin
# standalone): build tree in $NSCD_WS/build, devel space in $NSCD_WS/devel (default
# NSCD_WS: .build/ws in the repo). `source $NSCD_WS/devel/setup.bash` then puts the
# package on ROS_PACKAGE_PATH. The workspace holds no link back to the repository, so
# rosrun/roslaunch never crawl into a loop. Extra arguments are make targets ("tests").
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
jobs=${NSCD_JOBS:-$(nproc)}
mkdir -p "$ws"
# A workspace made by the former catkin_make build: its src/ links back to the repo.
if [ -L "$ws/src/nscd_sim" ]; then
  echo "removing the old catkin_make workspace in $ws"
  rm -rf "$ws/src" "$ws/build" "$ws/devel"
fi
# Each step chained with &&: `set -e` does not act inside a command whose status an
# `||` tests, so a failed build would otherwise go on and report success.
(
  cmake -S "$repo" -B "$ws/build" -DCMAKE_BUILD_TYPE=Release -DCATKIN_DEVEL_PREFIX="$ws/devel" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 &&
  cmake --build "$ws/build" -j"$jobs" &&
  for target in "$@"; do cmake --build "$ws/build" -j"$jobs" --target "$target" || exit 1; done
) > "$ws/build.log" 2>&1 || {
  tail -n 60 "$ws/build.log"; echo "build failed (full log: $ws/build.log)"; exit 1; }
echo "built in $ws (log: $ws/build.log); binaries in $ws/devel/lib/nscd_sim"
