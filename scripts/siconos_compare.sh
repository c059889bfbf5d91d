#!/usr/bin/env bash
# nscd_sim and Siconos side by side: the bouncing ball and the
# planar clearance pendulum, Moreau-Jean and combined projection, h = 1e-3 / 2^k,
# in one process; then errors, wall-time ratios and trajectory agreement.
#   scripts/siconos_compare.sh [OUT_DIR] [--quick]
# Needs the optional packages (scripts/install_siconos.sh) and a build
# (scripts/build.sh) that found them. Writes OUT_DIR/{runs.csv, samples.csv,
# summary.md, work_precision.png}; default OUT_DIR: build/siconos_compare.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
out=${1:-$repo/build/siconos_compare}
shift || true
exe=$ws/devel/lib/nscd_sim/nscd_siconos_compare
if [ ! -x "$exe" ]; then
  echo "no $exe: run scripts/install_siconos.sh, then scripts/build.sh" >&2
  exit 1
fi
mkdir -p "$out"
"$exe" --out "$out" "$@"
/usr/bin/python3 "$repo/scripts/analysis/siconos_compare.py" "$out"
echo "written: $out/summary.md $out/work_precision.png"
