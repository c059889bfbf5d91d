#!/usr/bin/env bash
# The test suite under AddressSanitizer and UndefinedBehaviorSanitizer
# (docs/fuzzing.md): a build of its own ($NSCD_WS, default build/asan) with the
# sanitizers in CXXFLAGS/LDFLAGS (no CMakeLists change) of only what is run, then
# every gtest, the pytest files through the instrumented module (python3 itself is
# not instrumented: libasan is preloaded, leak checks off for Python's own
# allocations) and one rostest (malformed_traffic: the node under bad traffic).
# Any sanitizer report fails the run, whichever process makes it (each writes
# its own file). Not part of CI: the build is long (docs/fuzzing.md).
#   scripts/sanitize.sh [CTEST_REGEX]   (default: the set above)
# Ends with "N passed, N failed, N sanitizer reports".
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
# Under build/: rosrun looks for an executable anywhere in the package but build/,
# and a second nscd_run elsewhere in it makes `rosrun nscd_sim nscd_run` ask which.
export NSCD_WS=${NSCD_WS:-$repo/build/asan}
ws=$NSCD_WS
# float-cast-overflow is not part of GCC's -fsanitize=undefined.
san="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize-recover=undefined,float-cast-overflow"
export CXXFLAGS="${CXXFLAGS:-} $san -fno-omit-frame-pointer -g"
export LDFLAGS="${LDFLAGS:-} -fsanitize=address,undefined"
jobs=${NSCD_JOBS:-$(nproc)}
# Configured as scripts/build.sh configures; built: only what the tests below run
# (the gtests, pulling in the tools they call, nscd_run, the Python module, the
# node and the malformed_traffic test node), not the benchmarks, the RViz panel or
# the other rostests' nodes (each compiles the node's sources again).
build_start=$(date +%s)
mkdir -p "$ws"
(
  cmake -S "$repo" -B "$ws/build" -DCMAKE_BUILD_TYPE=Release -DCATKIN_DEVEL_PREFIX="$ws/devel" \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 &&
  targets="nscd_run nscd_sim_node test_ros_malformed_traffic $(cd "$ws/build" &&
    ctest -N -R '^_ctest_nscd_sim_gtest_' | sed -n 's/.*_ctest_nscd_sim_gtest_//p' | tr '\n' ' ')" &&
  if cmake --build "$ws/build" --target help | grep ' nscd_sim_python$' > /dev/null; then
    targets="$targets nscd_sim_python"; fi &&
  echo "sanitize: building $targets" &&
  cmake --build "$ws/build" -j"$jobs" --target $targets
) > "$ws/build.log" 2>&1 || {
  tail -n 60 "$ws/build.log"; echo "sanitize: build failed (full log: $ws/build.log)"; exit 1; }
echo "sanitize: build $(( $(date +%s) - build_start )) s (log: $ws/build.log)"
tests_start=$(date +%s)

export ROS_HOME=$ws/ros_home
rm -rf "$ROS_HOME/log"
mkdir -p "$ROS_HOME"
# Every report goes to a file of its own (PREFIX.PID), whichever process makes it:
# a test's output is shown only when it fails, pytest keeps a subprocess's stderr
# to itself, and a node's leak report at shutdown fails no test.
reports_dir=$ws/sanitizer_reports
rm -rf "$reports_dir"
mkdir -p "$reports_dir"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1:log_path=$reports_dir/ubsan
# libstdc++ preloaded with libasan: python3 does not link it, and ASan's
# __cxa_throw interceptor, set up before libstdc++ is loaded, then has no real
# __cxa_throw to call ("CHECK failed ... real___cxa_throw", at the first C++ throw).
preload="$(g++ -print-file-name=libasan.so) $(g++ -print-file-name=libstdc++.so.6)"
regex=${1:-}
log=$ws/sanitize.log  # ctest's lines; every test's whole output in $output
output=$ws/sanitize_output.log
: > "$log"
: > "$output"
run_ctest() {  # REGEX, with the environment given
  (cd "$ws/build" && ctest --output-on-failure -j"${NSCD_TEST_JOBS:-2}" -R "$1" >> "$log" 2>&1) || true
  cat "$ws/build/Testing/Temporary/LastTest.log" >> "$output" 2>/dev/null || true
}
# Leaks inside Debian's HDF5 on a damaged file are HDF5's (fuzz/lsan_suppressions.txt);
# HDF5 asks for a damaged length's worth of memory (380 GB: tools/fclib/bad_files)
# and copes with NULL, which ASan then returns instead of aborting.
export LSAN_OPTIONS=suppressions=$repo/fuzz/lsan_suppressions.txt
ours=detect_leaks=1:allocator_may_return_null=1:log_path=$reports_dir/asan
if [ -n "$regex" ]; then
  ASAN_OPTIONS=$ours run_ctest "$regex"
else
  # Our executables: leaks checked too.
  ASAN_OPTIONS=$ours run_ctest '_gtest_|rostest_test_ros_malformed_traffic'
  # python3 loads the instrumented module: libasan first; Python's own lifetime
  # allocations are not leaks of ours.
  LD_PRELOAD=$preload ASAN_OPTIONS=detect_leaks=0:log_path=$reports_dir/asan run_ctest '^python_'
fi
passed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .* +Passed' "$log" || true)
failed=$(grep -Ec '^ *[0-9]+/[0-9]+ Test +#[0-9]+: .*(\*\*\*|Failed|Not Run|Exception)' "$log" || true)
pattern='ERROR: AddressSanitizer|ERROR: LeakSanitizer|runtime error:'
# The report files, and any report line that reached an output or a ROS log anyway.
reports=$( { grep -rhE "$pattern" "$reports_dir" "$log" "$output" "$ROS_HOME/log" 2>/dev/null || true; } | sort -u | wc -l)
if [ "$reports" -gt 0 ]; then
  grep -rE "$pattern" "$reports_dir" "$log" "$output" "$ROS_HOME/log" 2>/dev/null | head -n 20 || true
  echo "sanitize: the reports in full: $reports_dir"
fi
echo "sanitize: tests $(( $(date +%s) - tests_start )) s"
echo "$passed passed, $failed failed, $reports sanitizer reports (log: $log)"
[ "$failed" -eq 0 ] && [ "$reports" -eq 0 ] && [ "$passed" -gt 0 ]
