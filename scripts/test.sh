#!/usr/bin/env bash
# Builds (if needed) and runs every test (gtest unit tests and rostests) with ctest.
# Ends with "N passed, N failed"; exits non-zero if any test failed.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
export ROS_HOME=${ROS_HOME:-$ws/ros_home}
mkdir -p "$ROS_HOME"
"$repo/scripts/build.sh" tests
cd "$ws/build"
set +e
ctest --output-on-failure -j"${NSCD_TEST_JOBS:-2}" 2>&1 | tee "$ws/ctest.log"
rc=${PIPESTATUS[0]}
set -e
passed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* +Passed' "$ws/ctest.log" || true)
failed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .*(\*\*\*|Failed|Not Run|Exception)' "$ws/ctest.log" || true)
echo "$passed passed, $failed failed"
[ "$rc" -eq 0 ] && [ "$failed" -eq 0 ]
