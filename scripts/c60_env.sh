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
# The bench's table schedule (scripts/c60_bench.sh): settle 4 ms | forward 2 mm in 20 ms |
# hold 6 ms | back in 20 ms | hold 4 ms; each stroke eases in and out (smoothstep, sampled
# every 1 ms) so the table does not ring the mechanism.
C60_TABLE="table=$($PY -c "
pts = [(0, 0), (0.004, 0)]
for t0, x0, x1 in [(0.004, 0, 0.002), (0.030, 0.002, 0)]:
    for k in range(1, 21):
        s = k / 20; e = s * s * (3 - 2 * s)
        pts.append((t0 + 0.020 * s, x0 + (x1 - x0) * e))
    if t0 == 0.004: pts.append((0.030, 0.002))
pts.append((0.054, 0))
print(','.join('%.6g:%.9g' % p for p in pts))")"
