#!/usr/bin/env bash
# C-60 contact-force bench (seed paper section 4, Fig. 7), the package's main job.
# With the breaker ON (latched), a prescribed table pushes the moving contact away from the
# fixed contact by 2.0 mm and back, slowly (0.1 m/s, with holds); the table force is the
# contact force. Prints the equilibrium force (vs 15.28 N measured / 14.96 N simulated), the
# hysteresis and the joint polarisation; writes out/c60_bench.csv and docs/c60_bench*.png.
#   scripts/c60_bench.sh [SCENE.urdf] [extra nscd_run args...]
source "$(dirname "${BASH_SOURCE[0]}")/c60_env.sh"
scene=${1:-$C60_REPO/urdf/c60_bench.urdf}
shift || true
tag=${C60_TAG:-c60_bench}
png=${C60_PNG-$C60_DOCS/c60_bench.png}
table="$C60_TABLE"  # scripts/c60_env.sh
start=$(date +%s.%N)
"$NSCD_RUN" "$scene" --duration 0.054 --command "$table" --csv "$C60_OUT/$tag.csv" --every 5 --quiet "$@" \
  > "$C60_OUT/$tag.run.json"
wall=$(echo "$(date +%s.%N) - $start" | bc)
$PY "$C60_REPO/scripts/analysis/c60_plot.py" bench "$C60_OUT/$tag.csv" $png --json "$C60_OUT/$tag.json" > /dev/null
$PY - "$C60_OUT/$tag.json" "$C60_OUT/$tag.run.json" "$wall" <<'PYEOF'
import json, sys
r = json.load(open(sys.argv[1])); run = json.loads(open(sys.argv[2]).read().strip().splitlines()[-1])
print('C-60 contact-force bench (table 0 -> 2.0 mm -> 0)')
print('  equilibrium force at 2.0 mm : %.2f N   (paper: 15.28 N measured, 14.96 N simulated; %+.1f %% vs measured)'
      % (r['equilibrium_force_N'], r['rel_error_vs_measured_pct']))
print('  force at start / end of stroke: %.2f N -> %.2f N  (slope %.3f N/mm)'
      % (r['force_start_fwd_N'], r['force_end_fwd_N'], r['stiffness_fwd_N_per_mm']))
print('  hysteresis (forward - backward): mean %.3f N, max %.3f N, at 1 mm %.3f N'
      % (r['hysteresis_mean_N'], r['hysteresis_max_N'], r['hysteresis_at_1mm_N']))
print('  polarisation (e/c_r, direction in world deg)   before      at 2 mm')
for j in r['polarisation_before']:
    a, b = r['polarisation_before'][j], r['polarisation_at_2mm'][j]
    print('    %-3s  %5.2f @ %7.1f   %5.2f @ %7.1f' % (j, a['ecc'], a['dir_deg'], b['ecc'], b['dir_deg']))
print('  run: %d steps, wall %.1f s (%.1f s incl. plots), solver iterations mean %.0f, max penetration %.3g m'
      % (run['steps'], run['wall_s'], float(sys.argv[3]), run['iters_mean'], run['max_penetration']))
PYEOF
