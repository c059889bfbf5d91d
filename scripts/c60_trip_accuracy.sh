#!/usr/bin/env bash
# Accuracy per second of the C-60 trip (issue 29): touch, mean push, latch release and C7's
# opening of fixed-step and adaptive runs against a converged fixed-step reference (made once,
# under nice, and kept in .build/). One command, prints the table (docs/c60_convergence.md):
#   scripts/c60_trip_accuracy.sh                                   (fixed dt 1e-5, 1e-6, 2e-7, 1e-7)
#   scripts/c60_trip_accuracy.sh --fixed '' --adaptive 1e-3,1e-4   (adaptive, rtol = atol)
# Options: scripts/analysis/c60_trip_accuracy.py --help.
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
exec $PY "$C60_REPO/scripts/analysis/c60_trip_accuracy.py" "$@"
