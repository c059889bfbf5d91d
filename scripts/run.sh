#!/usr/bin/env bash
# Runs the built nscd_run with the given arguments (build it first: scripts/build.sh).
# `rosrun nscd_sim nscd_run ...` runs the same binary once the workspace is sourced.
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${NSCD_WS:-$repo/.build/ws}/devel/lib/nscd_sim/nscd_run
[ -x "$exe" ] || { echo "nscd_run is not built: run scripts/build.sh" >&2; exit 2; }
exec "$exe" "$@"
