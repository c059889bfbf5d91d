#!/usr/bin/env bash
# The C-60 trip from a settled rest (issue 29; docs/c60_convergence.md, section 3): one
# settling from the ON pose, stored with nscd_run --save-state in .build/, then the trip
# continued from it (nscd_run --initial-state) at fixed dt 2e-5 ... 2e-6 and adaptive
# tolerances, to 9.2 ms (C7 opens at ~8.85 ms); the four figures against a fixed-dt 5e-8
# continuation, and each run's wall (nscd_run's wall_s without CSV, best of 3). Prints the
# table and the cheapest run with every figure within 1 %:
#   scripts/c60_trip_from_rest.sh                       (the rest of fixed dt 2.5e-8)
#   scripts/c60_trip_from_rest.sh --rest-dt 1e-6        (another rest)
# Options: scripts/analysis/c60_trip_from_rest.py --help.
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
exec $PY "$C60_REPO/scripts/analysis/c60_trip_from_rest.py" "$@"
