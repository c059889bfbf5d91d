#!/usr/bin/env bash
# The C-60's probe dragged in RViz, off-screen (RViz under Xvfb): launch/c60.launch
# (the node with config/c60.yaml and nscd_actuator_markers), the probe's marker
# dragged to 3 mm by scripts/c60_drag.py as RViz would send it, the node stepped 1 ms
# per frame. Writes docs/images/c60_drag.gif (14 frames, 640 px wide) and
# docs/images/c60_drag.png (1280x720, after the release).
#   scripts/c60_drag.sh [extra scripts/record_video.sh options, e.g. -o out/drag.png]
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
exec "$here/record_video.sh" --launch c60.launch --scene "$repo/urdf/c60.urdf" \
  --config "$repo/config/c60.yaml" --rviz "$repo/config/c60.rviz" --size 1280x720 \
  --drive "$here/c60_drag.py" --output "$repo/docs/images/c60_drag.png" "$@"
