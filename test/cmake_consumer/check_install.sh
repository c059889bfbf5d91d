#!/usr/bin/env bash
# The engine without ROS, end to end (README "Building without ROS", docs/python.md):
#   1. configures the repository with plain CMake, once with -DNSCD_ROS=OFF and once
#      with catkin hidden (as on a machine without ROS): each says in one line that
#      the ROS parts are skipped;
#   2. builds it and installs it into WORKDIR/prefix (cmake --install --prefix);
#   3. the install holds the library, headers, nscd_run, nscd_sweep, the package
#      config and the Python package, and nothing of ROS;
#   4. builds test/cmake_consumer against it with find_package(nscd_engine) and runs
#      it (a ball's free fall and bounce, checked against the scheme);
#   5. imports nscd_sim from the prefix alone and runs the Python tests that compare
#      the module with nscd_run (both the installed ones) and the study runner.
# Usage: check_install.sh WORKDIR   (build tree WORKDIR/build; NSCD_JOBS: build jobs)
# WORKDIR inside the repository must be under build/: rosrun skips that folder, while a
# second nscd_run anywhere else in the package makes `rosrun nscd_sim nscd_run` ask
# which one (and the ROS tool tests fail).
# Ends with "check_install: ok" or a message naming what failed, and status 1.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
[ $# -eq 1 ] || { echo "usage: check_install.sh WORKDIR" >&2; exit 2; }
work=$(realpath -m "$1")
build=$work/build prefix=$work/prefix
jobs=${NSCD_JOBS:-$(nproc)}
fail() { echo "check_install: FAILED: $*" >&2; exit 1; }
skip_line='nscd_sim: ROS parts skipped'
case "$work/" in
  "$repo/build/"*) ;;
  "$repo/"*) fail "WORKDIR $work: inside the repository, only under $repo/build/ (rosrun skips it)";;
esac
mkdir -p "$work"

rm -rf "$prefix" "$work/consumer"
cmake -S "$repo" -B "$build" -DNSCD_ROS=OFF > "$work/configure_off.log" 2>&1 ||
  { cat "$work/configure_off.log"; fail "configure with -DNSCD_ROS=OFF"; }
[ "$(grep -c "$skip_line" "$work/configure_off.log")" -eq 1 ] || fail "-DNSCD_ROS=OFF: no '$skip_line' line"
cmake -S "$repo" -B "$build" -UNSCD_ROS -DCMAKE_DISABLE_FIND_PACKAGE_catkin=ON > "$work/configure.log" 2>&1 ||
  { cat "$work/configure.log"; fail "configure without catkin"; }
[ "$(grep -c "$skip_line" "$work/configure.log")" -eq 1 ] || fail "without catkin: no '$skip_line' line"
grep "$skip_line" "$work/configure.log"

cmake --build "$build" -j"$jobs" > "$work/build.log" 2>&1 || { tail -n 40 "$work/build.log"; fail "build"; }
cmake --install "$build" --prefix "$prefix" > "$work/install.log" 2>&1 || { cat "$work/install.log"; fail "install"; }

libdir=$(sed -n 's/^CMAKE_INSTALL_LIBDIR:[A-Z]*=//p' "$build/CMakeCache.txt")
pydir=$prefix/$(sed -n 's/^NSCD_PYTHON_INSTALL_DIR:[A-Z]*=//p' "$build/CMakeCache.txt")
for f in bin/nscd_run bin/nscd_sweep "$libdir/libnscd_engine.a" include/nscd_sim/simulator.hpp \
         "$libdir/cmake/nscd_engine/nscd_engineConfig.cmake" share/nscd_sim/urdf/ball.urdf; do
  [ -e "$prefix/$f" ] || fail "not installed: $f"
done
for f in __init__.py study.py; do [ -e "$pydir/nscd_sim/$f" ] || fail "not installed: $pydir/nscd_sim/$f"; done
ls "$pydir"/nscd_sim/_engine*.so > /dev/null 2>&1 || fail "not installed: the module $pydir/nscd_sim/_engine*.so"
if find "$prefix" -name 'nscd_sim_node' -o -name '*.msg' -o -name '*rviz*' | grep -q .; then
  fail "ROS parts installed: $(find "$prefix" -name 'nscd_sim_node' -o -name '*.msg' -o -name '*rviz*')"
fi
echo "installed in $prefix: $(find "$prefix" -type f | wc -l) files"

# A C++ consumer: find_package(nscd_engine), the imported target, the installed scene.
cmake -S "$repo/test/cmake_consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
  > "$work/consumer.log" 2>&1 && cmake --build "$work/consumer" >> "$work/consumer.log" 2>&1 ||
  { cat "$work/consumer.log"; fail "the consumer project does not build against the install"; }
"$work/consumer/ball_drop" "$prefix/share/nscd_sim/urdf/ball.urdf" || fail "the consumer's checks"

# Python from the prefix alone (run outside the repository: its python/ is not on the path).
where=$(cd / && PYTHONPATH="$pydir" /usr/bin/python3 -c 'import nscd_sim, nscd_sim.study
s = nscd_sim.Simulator("'"$prefix"'/share/nscd_sim/urdf/ball.urdf")
r = s.run(0.1)
assert len(r) == 1001 and r["ball.z"][-1] < r["ball.z"][0], r["ball.z"][-1]
print(nscd_sim.__file__, nscd_sim._engine.__file__)') || fail "import nscd_sim from $pydir"
case "$where" in "$pydir/nscd_sim/__init__.py $pydir/nscd_sim/_engine"*) ;; *) fail "nscd_sim imported from $where, not $pydir";; esac
echo "nscd_sim imports from the prefix: $where"
# The module's records are nscd_run's CSV, character for character (both installed);
# the study runner's processes, shards, LocalCluster and command line.
(cd "$repo/test/python" && PYTHONPATH="$pydir" PYTHONDONTWRITEBYTECODE=1 NSCD_SOURCE_DIR="$repo" \
  NSCD_RUN_EXE="$prefix/bin/nscd_run" /usr/bin/python3 -m pytest -q -p no:cacheprovider \
  test_csv_identity.py test_study.py) || fail "the Python tests against the install"
echo "check_install: ok"
