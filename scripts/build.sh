#!/usr/bin/env bash
# Builds nscd_sim (Release) in a catkin workspace: $NSCD_WS (default: .build/ws in the repo;
# hidden, so that roslaunch does not crawl back into the repo through the workspace's
# src/nscd_sim, which is a symlink to this repository).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
mkdir -p "$ws/src"
ln -sfn "$repo" "$ws/src/nscd_sim"
jobs=${NSCD_JOBS:-$(nproc)}
cd "$ws"
catkin_make -DCMAKE_BUILD_TYPE=Release -j"$jobs" "$@" > "$ws/build.log" 2>&1 || {
  tail -n 60 "$ws/build.log"; echo "build failed (full log: $ws/build.log)"; exit 1; }
echo "built in $ws (log: $ws/build.log); binaries in $ws/devel/lib/nscd_sim"
