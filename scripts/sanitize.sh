#!/usr/bin/env bash
# The test suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (docs/fuzzing.md): a build of its own ($NSCD_WS, default .build/asan) with the
# sanitizers in CXXFLAGS/LDFLAGS (no CMakeLists change), then every gtest, the
# pytest files through the instrumented module (python3 itself is not
# instrumented: libasan is preloaded, leak checks off for Python's own
# allocations) and one rostest (malformed_traffic: the node under bad traffic).
# Any sanitizer report fails the run, also one in a ROS log. Not part of CI: the
# build alone takes ~15 min on 2 cores.
#   scripts/sanitize.sh [CTEST_REGEX]   (default: the set above)
# Ends with "N passed, N failed, N sanitizer reports".
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export NSCD_WS=${NSCD_WS:-$repo/.build/asan}
ws=$NSCD_WS
# float-cast-overflow is not part of GCC's -fsanitize=undefined.
san="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=undefined,float-cast-overflow"
export CXXFLAGS="${CXXFLAGS:-} $san -fno-omit-frame-pointer -g"
export LDFLAGS="${LDFLAGS:-} -fsanitize=address,undefined"
"$repo/scripts/build.sh" tests

export ROS_HOME=$ws/ros_home
rm -rf "$ROS_HOME/log"
mkdir -p "$ROS_HOME"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
libasan=$(g++ -print-file-name=libasan.so)
regex=${1:-}
log=$ws/sanitize.log
: > "$log"
run_ctest() {  # REGEX, with the environment given
  (cd "$ws/build" && ctest --output-on-failure -j"${NSCD_TEST_JOBS:-2}" -R "$1" >> "$log" 2>&1) || true
}
# Leaks inside Debian's HDF5 on a damaged file are HDF5's (fuzz/lsan_suppressions.txt);
# HDF5 asks for a damaged length's worth of memory (380 GB: tools/fclib/bad_files)
# and copes with NULL, which ASan then returns instead of aborting.
export LSAN_OPTIONS=suppressions=$repo/fuzz/lsan_suppressions.txt
ours=detect_leaks=1:allocator_may_return_null=1
if [ -n "$regex" ]; then
  ASAN_OPTIONS=$ours run_ctest "$regex"
else
  # Our executables: leaks checked too.
  ASAN_OPTIONS=$ours run_ctest '_gtest_|rostest_test_ros_malformed_traffic'
  # python3 loads the instrumented module: libasan first; Python's own lifetime
  # allocations are not leaks of ours.
  LD_PRELOAD=$libasan ASAN_OPTIONS=detect_leaks=0 run_ctest '^python_'
fi
passed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* +Passed' "$log" || true)
failed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .*(\*\*\*|Failed|Not Run|Exception)' "$log" || true)
pattern='ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:'
reports=$( { grep -E "$pattern" "$log" || true; grep -rhE "$pattern" "$ROS_HOME/log" 2>/dev/null || true; } | wc -l)
if [ "$reports" -gt 0 ]; then
  { grep -E "$pattern" "$log"; grep -rE "$pattern" "$ROS_HOME/log" 2>/dev/null; } | head -n 20 || true
fi
echo "$passed passed, $failed failed, $reports sanitizer reports (log: $log)"
[ "$failed" -eq 0 ] && [ "$reports" -eq 0 ] && [ "$passed" -gt 0 ]
