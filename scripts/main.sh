#!/usr/bin/env bash
# The main job: install what is missing, build, and run the C-60 contact-force
# bench headless (seed paper section 4, Fig. 7). Prints the key figures
# (equilibrium force vs the paper's 15.28 N, hysteresis, joint polarisation) and
# writes the plots (docs/c60_bench*.png) and the CSV (out/).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$repo/scripts/deps.sh"
bash "$repo/scripts/build.sh"
bash "$repo/scripts/c60_bench.sh"
