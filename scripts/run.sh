#!/usr/bin/env bash
# Runs the built nscd_run (build it first with scripts/build.sh).
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
exe=${NSCD_WS:-$repo/.build/ws}/devel/lib/nscd_sim/nscd_run
[ -x "$exe" ] || { echo "nscd_run is not built: run scripts/build.sh" >&2; exit 2; }
exec "$exe" "$@"
