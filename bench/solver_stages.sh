#!/usr/bin/env bash
# How many solves each stage of the solver's schedule finishes, and how many steps
# take each rescue (docs/solver.md), over the corpus: the 16 C-60 scenarios of
# scripts/c60_scenarios.sh (rest, trip, bench, handle x paper, ideal) at dt 1e-5 and
# 1e-6, and the stress suite's seeds 1-3.
#   bench/solver_stages.sh [--quick] [--dump STAGE,...] [OUT]     (default OUT build/solver_stages)
# --quick: dt 1e-5 and seed 1 only (~1 min; the whole corpus ~3.5 min of CPU, one run
# after the other).
# --dump: also write the problems those stages finished, OUT/dump/RUN/ (the input of
# bench/solver_stage_needs.py; the deep stages of the whole corpus take ~3 GB).
# Writes OUT/RUN.json (each run's summary line) and prints the table of counts.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${NSCD_WS:-$repo/.build/ws}/devel/lib/nscd_sim
dts="1e-5 1e-6" seeds="1 2 3" stages=""
while [ $# -gt 0 ]; do
  case $1 in
    --quick) dts="1e-5"; seeds="1"; shift ;;
    --dump) stages=$2; shift 2 ;;
    *) break ;;
  esac
done
out=${1:-$repo/build/solver_stages}
mkdir -p "$out"
NSCD_RUN=$bin/nscd_run source "$repo/scripts/c60_env.sh"
source "$repo/scripts/c60_scenarios.sh"
dump() {  # the dump options for run $1
  [ -n "$stages" ] || return 0
  mkdir -p "$out/dump/$1"
  echo --dump-problems "$out/dump/$1" --dump-when "stage=$stages"
}
for dt in $dts; do
  for model in $C60_MODELS; do
    for sc in $C60_SCENARIOS; do
      c60_scenario_args "$sc" "$model"
      tag=c60_${sc}_${model}_$dt
      # shellcheck disable=SC2046
      "$bin/nscd_run" "${c60_args[@]}" --dt "$dt" --quiet $(dump "$tag") 2>/dev/null | tail -n 1 > "$out/$tag.json"
    done
  done
done
for seed in $seeds; do
  # shellcheck disable=SC2046
  "$bin/nscd_stress" --seed "$seed" --quiet $(dump "stress$seed") > "$out/stress$seed.json" 2>/dev/null || true
done
/usr/bin/python3 - "$out" <<'EOF'
import glob, json, os, sys
out = sys.argv[1]
groups = {}
for f in sorted(glob.glob(os.path.join(out, '*.json'))):
    tag = os.path.basename(f)[:-5]
    d = json.loads(open(f).read())
    g = 'stress' if tag.startswith('stress') else 'C-60 dt ' + tag.rsplit('_', 1)[1]
    acc = groups.setdefault(g, {'solver_stages': {}, 'rescues': {}, 'steps': 0, 'unconverged': 0})
    acc['steps'] += d.get('total_steps', d.get('steps', 0))
    acc['unconverged'] += d['unconverged_steps']
    for k in ('solver_stages', 'rescues'):
        for n, v in d[k].items():
            acc[k][n] = acc[k].get(n, 0) + v
cols = sorted(groups, key=lambda c: (c == 'stress', c))
for key, title in (('solver_stages', 'stage (solves)'), ('rescues', 'rescue (steps)')):
    print(f'| {title} | ' + ' | '.join(cols) + ' | all |')
    print('|---|' + '---:|' * (len(cols) + 1))
    for n in groups[cols[0]][key]:
        vals = [groups[c][key][n] for c in cols]
        print(f'| `{n}` | ' + ' | '.join(str(v) for v in vals) + f' | {sum(vals)} |')
    print()
print('| steps | ' + ' | '.join(str(groups[c]['steps']) for c in cols) + ' | |')
print('| unconverged steps | ' + ' | '.join(str(groups[c]['unconverged']) for c in cols) + ' | |')
EOF
