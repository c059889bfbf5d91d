#!/usr/bin/env bash
# The solver on large stacks (docs/solver.md, "Large stacks"): box pyramids of 84
# and 100 frictional contacts (bench/box_pyramid.py: a base of 6 in 6 layers, of 7
# in 5), at rest on a 10 degree slope (mu 0.5, dropped 1 mm) and sliding down a 15
# degree one (mu 0.2, dropped 0.1 mm). Each is run 0.1 s at dt 1e-3 with every
# problem dumped; those with all their contacts active are solved again cold (P = 0,
# as the FCLib sets are) and from the run's warm start, at 1e-8 and 1e-10, by the
# default schedule and, for comparison, by SolverMethod::ProximalNewton (--method prox).
#   bench/solver_stacks.sh [--problems DIR] [OUT]   (default OUT build/solver_stacks; ~3 min)
# --problems DIR: solve the problems an earlier run dumped into DIR (its OUT) instead of
# running the stacks again: the runs' trajectories, hence their problems, change with
# the solver, so two builds are compared on one set this way.
# Prints per set and setting: problems solved, the stages that finished them, the
# sweeps and Newton iterations per problem (for the proximal Newton: its inner
# Newton iterations, each a factorisation as the Newton's are), and the mean time per problem, the fastest of
# 3 solves each (this machine, now: compare within one run).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${NSCD_WS:-$repo/.build/ws}/devel/lib/nscd_sim
problems=""
if [ "${1:-}" = "--problems" ]; then problems=$(cd "$2" && pwd); shift 2; fi
out=${1:-$repo/build/solver_stacks}
rm -rf "$out"
mkdir -p "$out"
printf '| set | contacts | start | tol | method | solved | stages | sweeps | Newton iterations | ms per problem |\n|---|---:|---|---|---|---|---|---:|---:|---:|\n'
for set in "6 6 rest" "6 6 slide" "7 5 rest" "7 5 slide"; do
  read -r base layers kind <<< "$set"
  case $kind in
    rest) opts=(--mu 0.5 --tilt 10 --drop 1e-3) ;;
    slide) opts=(--mu 0.2 --tilt 15 --drop 1e-4) ;;
  esac
  name=pyramid${base}_${layers}_$kind
  /usr/bin/python3 "$repo/bench/box_pyramid.py" --base "$base" --layers "$layers" "${opts[@]}" > "$out/$name.urdf"
  contacts=$(grep -c '<contact ' "$out/$name.urdf")
  mkdir -p "$out/$name"
  if [ -n "$problems" ]; then
    cp "$problems/$name"/*.txt "$out/$name/"
  else
    "$bin/nscd_run" "$out/$name.urdf" --duration 0.1 --quiet --dump-problems "$out/$name" --dump-when all > /dev/null 2>&1
  fi
  full=()
  for f in "$out/$name"/*.txt; do
    [ "$(sed -n 2p "$f" | awk '{print $6}')" -eq $((3 * contacts)) ] && full+=("$f")
  done
  for start in cold warm; do
    for tol in 1e-8 1e-10; do
      for method in auto prox; do
        cold=(); [ $start = cold ] && cold=(--cold)
        "$bin/nscd_solve_problems" --tol "$tol" --method "$method" --repeat 3 "${cold[@]}" "${full[@]}" > "$out/$name.$start.$tol.$method.txt"
        /usr/bin/python3 - "$out/$name.$start.$tol.$method.txt" "$name" "$contacts" "$start" "$tol" "$method" <<'EOF'
import sys
path, name, contacts, start, tol, method = sys.argv[1:]
lines = open(path).read().splitlines()
stages = next(l for l in lines if l.startswith('stages:')).split()[1:]
solved = next(l for l in lines if l.startswith('solved')).replace(',', '').split()
n, of, us = int(solved[1]), int(solved[3]), float(solved[7])
rows = [l.split() for l in lines[1:] if len(l.split()) == 9 and l.split()[2] in ('yes', 'NO')]
sweeps = sum(int(r[4]) for r in rows) / len(rows)   # per problem
newton = sum(int(r[5]) for r in rows) / len(rows)
st = ', '.join(f'{stages[i]} {stages[i + 1]}' for i in range(0, len(stages), 2))
print(f'| {name} | {contacts} | {start} | {tol} | {method} | {n} of {of} | {st} | {sweeps:.1f} | {newton:.1f} | {us / 1000 / of:.2f} |')
EOF
      done
    done
  done
done
