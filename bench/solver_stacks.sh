#!/usr/bin/env bash
# The solver on large stacks (docs/solver.md, "Large stacks"): box pyramids of 84
# and 100 frictional contacts (bench/box_pyramid.py: a base of 6 in 6 layers, of 7
# in 5), at rest on a 10 degree slope (mu 0.5, dropped 1 mm) and sliding down a 15
# degree one (mu 0.2, dropped 0.1 mm). Each is run 0.1 s at dt 1e-3 with every
# problem dumped; those with all their contacts active are solved again cold (P = 0,
# as the FCLib sets are) and from the run's warm start, at 1e-8 and 1e-10, by the
# default schedule and, for comparison, by SolverMethod::ProximalNewton (--method prox).
#   bench/solver_stacks.sh [OUT]        (default build/solver_stacks; ~2 min)
# Prints per set and setting: problems solved, the stages that finished them, the
# iterations, and the mean time per problem (this machine, now: compare within one run).
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bin=${NSCD_WS:-$repo/.build/ws}/devel/lib/nscd_sim
out=${1:-$repo/build/solver_stacks}
rm -rf "$out"
mkdir -p "$out"
printf '| set | contacts | start | tol | method | solved | stages | iterations | ms per problem |\n|---|---:|---|---|---|---|---|---:|---:|\n'
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
  "$bin/nscd_run" "$out/$name.urdf" --duration 0.1 --quiet --dump-problems "$out/$name" --dump-when all > /dev/null 2>&1
  full=()
  for f in "$out/$name"/*.txt; do
    [ "$(sed -n 2p "$f" | awk '{print $6}')" -eq $((3 * contacts)) ] && full+=("$f")
  done
  for start in cold warm; do
    for tol in 1e-8 1e-10; do
      for method in auto prox; do
        cold=(); [ $start = cold ] && cold=(--cold)
        "$bin/nscd_solve_problems" --tol "$tol" --method "$method" "${cold[@]}" "${full[@]}" > "$out/$name.$start.$tol.$method.txt"
        /usr/bin/python3 - "$out/$name.$start.$tol.$method.txt" "$name" "$contacts" "$start" "$tol" "$method" <<'EOF'
import sys
path, name, contacts, start, tol, method = sys.argv[1:]
lines = open(path).read().splitlines()
stages = next(l for l in lines if l.startswith('stages:')).split()[1:]
solved = next(l for l in lines if l.startswith('solved')).replace(',', '').split()
n, of, iters, us = int(solved[1]), int(solved[3]), int(solved[5]), float(solved[7])
st = ', '.join(f'{stages[i]} {stages[i + 1]}' for i in range(0, len(stages), 2))
print(f'| {name} | {contacts} | {start} | {tol} | {method} | {n} of {of} | {st} | {iters} | {us / 1000 / of:.2f} |')
EOF
      done
    done
  done
done
