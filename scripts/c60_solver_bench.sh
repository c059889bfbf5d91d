#!/usr/bin/env bash
# The contact solver on the C-60's scenarios: per scenario, model and time step,
# unconverged steps, iterations (mean / max), the largest residual, the fallback
# steps (frictionless re-solve, energy cap) and the wall time.
#   scripts/c60_solver_bench.sh [--quick]     (--quick: dt 1e-5 only)
# The scenarios and models: scripts/c60_scenarios.sh.
# Wall times are of this machine, now: compare them within one run.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
run=$ws/devel/lib/nscd_sim/nscd_run
[ -x "$run" ] || { echo "no $run: run scripts/build.sh" >&2; exit 1; }
source "$repo/scripts/c60_env.sh"
source "$repo/scripts/c60_scenarios.sh"
dts="1e-5 1e-6"
[ "${1:-}" = "--quick" ] && dts="1e-5"
printf "%-7s %-6s %-6s %7s %7s %6s %9s %5s %5s %8s\n" scenario model dt unconv it_mean it_max res_max fb_fl fb_cap wall_s
for dt in $dts; do
  for model in $C60_MODELS; do
    for sc in $C60_SCENARIOS; do
      c60_scenario_args "$sc" "$model"
      json=$("$run" "${c60_args[@]}" --dt "$dt" --quiet 2>/dev/null | tail -n 1) || true
      /usr/bin/python3 -c "
import json, sys
d = json.loads(sys.argv[1])
print('%-7s %-6s %-6s %7d %7.1f %6d %9.2e %5d %5d %8.2f' % ('$sc', '$model', '$dt', d['unconverged_steps'],
      d['iters_mean'], d['iters_max'], d['residual_max'], d['frictionless_fallbacks'],
      d['energy_capped_steps'], d['wall_s']))" "$json"
    done
  done
done
