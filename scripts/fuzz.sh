#!/usr/bin/env bash
# The libFuzzer targets (fuzz/, docs/fuzzing.md): builds what a run needs with
# clang (ASan + UBSan) into $NSCD_FUZZ_DIR (default .build/fuzz, git-ignored) and
# runs one target, or all of them one after the other.
#   scripts/fuzz.sh --list                   the targets, one a line
#   scripts/fuzz.sh TARGET SECONDS [OPT...]   one target for SECONDS (OPT: libFuzzer options)
#   scripts/fuzz.sh --all SECONDS            every target for SECONDS each (CI)
#   scripts/fuzz.sh --build                  only build
# NSCD_FUZZ_OPT: the build's optimisation (default -O2, which CI uses; -O1 builds sooner).
# Prints the executions per second, the coverage (edges) and features reached;
# exits non-zero if a target crashed, hung, leaked or a sanitizer or an oracle
# fired (the input is kept in $NSCD_FUZZ_DIR/artifacts/TARGET/). The corpus grows
# in $NSCD_FUZZ_DIR/corpus/TARGET, seeded from the repository's files (never
# written to).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dir=${NSCD_FUZZ_DIR:-$repo/.build/fuzz}
jobs=${NSCD_JOBS:-$(nproc)}

# TARGET | dictionary (- for none) | seed folders (in the repository) | per-input
# time limit, s (scene_loader 180: a fuzzed C-60 that assembles after 16 projection
# passes of 100-150 rows took 51 s under the fuzz build on an idle machine, and
# CI's machine has run inputs at half that speed) | "master" if it
# reads parameters from a ROS master (a private one is started)
targets="
scene_loader|scene|urdf test/scenes test/scenes/bad test/ros|180
command_schedule|schedule|fuzz/seeds/command_schedule|10
set_option|settings|fuzz/seeds/set_option|20
settings_yaml|settings|fuzz/seeds/settings_yaml config|20
problem_file|problem|test/problems|20
stepping|stepping|fuzz/seeds/stepping|60
state_file|state|fuzz/seeds/state_file|20
fclib_from_nscd|problem|test/problems|20
fclib_reader|-||20
node_config|settings|config fuzz/seeds/settings_yaml|20|master
"

field() {  # TARGET N: the Nth field of TARGET's line
  echo "$targets" | awk -F'|' -v t="$1" -v n="$2" '$1 == t { print $n }'
}

built=""  # the targets build() made
build() {  # TARGET...: configures and builds those this machine has the libraries of, and the dictionaries
  mkdir -p "$dir"
  CXX=${NSCD_FUZZ_CXX:-clang++-14} cmake -S "$repo/fuzz" -B "$dir/build" \
    ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER} \
    -DNSCD_FUZZ_OPT="${NSCD_FUZZ_OPT:--O2}" \
    > "$dir/configure.log" 2>&1 || { tail -n 30 "$dir/configure.log"; echo "fuzz: configure failed"; exit 1; }
  local t known targets_to_build=(make_dictionaries)
  known=$(cmake --build "$dir/build" --target help 2>/dev/null)
  built=""
  for t in "$@"; do
    if grep -q " ${t}_fuzzer\$" <<< "$known"; then
      targets_to_build+=("${t}_fuzzer")
      built="$built $t"
    else
      echo "fuzz: $t is not built here: $(grep -i "no ${t} fuzz target" "$dir/configure.log" | sed 's/^-- //' | head -n 1)"
    fi
  done
  cmake --build "$dir/build" -j"$jobs" --target "${targets_to_build[@]}" > "$dir/build.log" 2>&1 ||
    { tail -n 40 "$dir/build.log"; echo "fuzz: build failed (log: $dir/build.log)"; exit 1; }
  mkdir -p "$dir/dict"
  "$dir/build/make_dictionaries" "$dir/dict"
}

run() {  # TARGET SECONDS [OPT...]: one run; its summary line; non-zero on a finding
  local t=$1 seconds=$2
  shift 2
  local seeds=() s
  for s in $(field "$t" 3); do seeds+=("$repo/$s"); done
  # The inputs of past findings (each also a test of the suite) run first.
  [ ! -d "$repo/fuzz/regressions/$t" ] || seeds+=("$repo/fuzz/regressions/$t")
  mkdir -p "$dir/corpus/$t" "$dir/artifacts/$t" "$dir/logs"
  local log=$dir/logs/$t.log status=0
  local start master_pid="" options=()
  [ "$(field "$t" 2)" = - ] || options+=(-dict="$dir/dict/$(field "$t" 2).dict")
  if [ "$(field "$t" 5)" = master ]; then
    local port
    port=$(/usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')
    export ROS_MASTER_URI=http://127.0.0.1:$port ROS_IP=127.0.0.1 ROS_HOME=$dir/ros_home
    unset ROS_HOSTNAME
    setsid rosmaster --core -p "$port" > "$dir/logs/$t.master.log" 2>&1 &
    master_pid=$!
    for _ in $(seq 100); do rosparam list > /dev/null 2>&1 && break; sleep 0.1; done
  fi
  start=$(date +%s)
  # Run from the artifacts folder: libFuzzer writes crash-*, timeout-* there.
  ( cd "$dir/artifacts/$t" &&
    ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1} \
    LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$repo/fuzz/lsan_suppressions.txt} \
    UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1} \
    "$dir/build/${t}_fuzzer" -max_total_time="$seconds" -timeout="$(field "$t" 4)" \
      -artifact_prefix="$dir/artifacts/$t/" \
      -rss_limit_mb=2048 -print_final_stats=1 "${options[@]}" "$@" "$dir/corpus/$t" "${seeds[@]}" ) > "$log" 2>&1 || status=$?
  local wall=$(( $(date +%s) - start ))
  # rosmaster ignores SIGINT when started in the background: SIGTERM.
  [ -z "$master_pid" ] || { kill -TERM "$master_pid" 2>/dev/null; wait "$master_pid" 2>/dev/null || true; }
  local execs rate cov ft corp
  execs=$(grep -Eo 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -Eo '[0-9]+$' || true)
  rate=$(grep -Eo 'stat::average_exec_per_sec: *[0-9]+' "$log" | grep -Eo '[0-9]+$' || true)
  cov=$(grep -Eo 'cov: [0-9]+' "$log" | tail -n 1 | grep -Eo '[0-9]+' || true)
  ft=$(grep -Eo 'ft: [0-9]+' "$log" | tail -n 1 | grep -Eo '[0-9]+' || true)
  corp=$(grep -Eo 'corp: [0-9]+/[0-9]+[a-zA-Z]*' "$log" | tail -n 1 | cut -d' ' -f2 || true)
  printf '%-17s %5d s  %9s execs  %6s execs/s  cov %6s  ft %6s  corpus %s  %s\n' "$t" "$wall" \
    "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" \
    "$([ "$status" -eq 0 ] && echo "no crash" || echo "FINDING (status $status)")"
  if [ "$status" -ne 0 ]; then
    grep -E 'ERROR: |runtime error|nscd fuzz oracle|SUMMARY|Test unit written' "$log" | head -n 8
    echo "fuzz: $t: see $log; the input is in $dir/artifacts/$t/"
  fi
  return "$status"
}

all_targets=$(echo "$targets" | awk -F'|' 'NF { print $1 }')
case "${1:-}" in
  --list) echo "$all_targets" ;;
  --build) build $all_targets ;;
  --all)
    [ $# -eq 2 ] || { echo "usage: $0 --all SECONDS"; exit 2; }
    build $all_targets
    findings=""
    for t in $built; do run "$t" "$2" || findings="$findings $t"; done
    if [ -n "$findings" ]; then
      echo "fuzz: FINDING in:$findings (inputs in $dir/artifacts/TARGET/)"
      exit 1
    fi
    echo "fuzz: no finding ($(echo $built | wc -w) targets, $2 s each)"
    exit 0 ;;
  ""|-h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
  *)
    [ $# -ge 2 ] || { echo "usage: $0 TARGET SECONDS [libFuzzer options]"; exit 2; }
    [ -n "$(field "$1" 1)" ] || { echo "fuzz: unknown target '$1' (scripts/fuzz.sh --list)"; exit 2; }
    build "$1"
    [ -n "$built" ] || exit 1
    run "$@" ;;
esac
