#!/usr/bin/env bash
# Video of the C-60 trip, off-screen (RViz under Xvfb): the probe pushes the tripping
# bar, the latch releases, the contacts open. 1 ms of simulation = 1 s of video
# (config/c60_trip.yaml), 1600x900 at 15 fps: the part meshes, the labelled force arrows
# and the arrow scale, the eccentricity rings, the status text with the sim time, the
# event labels, and the KeyFigures panel plotting the tripping force TRIP.fn.
# Writes out/c60_trip.mp4 and out/c60_trip.png (at 9 s: 9 ms).
#   scripts/c60_video.sh [extra scripts/record_video.sh options, e.g. -o FILE]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
exec "$here/record_video.sh" --scene "$repo/urdf/c60.urdf" --config "$repo/config/c60_trip.yaml" \
  --rviz "$repo/config/c60.rviz" --keep-panel nscd_sim/KeyFigures --size 1600x900 --duration 13 --snapshot-at 9 \
  --output "$repo/out/c60_trip.mp4" "$@"
