# Sourced by the scripts/c60_*.sh scenario commands: paths and the nscd_run binary.
# NSCD_RUN overrides the binary (default: the catkin build of scripts/build.sh).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
C60_REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
C60_OUT=${C60_OUT:-$C60_REPO/out}
C60_DOCS=${C60_DOCS:-$C60_REPO/docs}
NSCD_RUN=${NSCD_RUN:-$C60_REPO/.build/ws/devel/lib/nscd_sim/nscd_run}
if [ ! -x "$NSCD_RUN" ]; then
  echo "nscd_run not found at $NSCD_RUN: run scripts/build.sh first (or set NSCD_RUN)" >&2
  exit 1
fi
mkdir -p "$C60_OUT"
PY=/usr/bin/python3
# The probe schedule of the public model: still until 0.7 ms, then 0.2 m/s along +x.
C60_PROBE="probe=0:0,0.0007:0,0.0207:0.004"
