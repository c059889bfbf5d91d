#!/usr/bin/env bash
# nscd_sim and MuJoCo side by side: a pendulum, a double pendulum, a four-bar and a
# ball (bench/mujoco/), every run to t = 1 s against an engine-free converged
# reference; MuJoCo's Euler and RK4 at several dt, ours fixed at several dt and
# adaptive at several tolerances, in one process. Prints the tables of
# docs/mujoco_comparison.md.
#   scripts/mujoco_compare.sh [OUT_DIR] [--quick] [--instructions] [--adaptive-dt=S]
# --adaptive-dt=S: the largest step of our adaptive runs (their dt; default 0.01).
# --quick: a few runs per engine (seconds); --instructions: also the instructions of
# one step at dt 1e-4 (valgrind's callgrind, 2000 steps inside nscd::Simulator::step()
# and mj_step). Needs Debian's libmujoco-dev (sudo apt-get install libmujoco-dev) and a
# build that found it (scripts/build.sh). Writes OUT_DIR/{runs.csv, references.csv,
# instructions.csv, load.txt, summary.md}; default OUT_DIR: build/mujoco_compare.
set -euo pipefail
export PATH=/usr/bin:/bin:/usr/sbin:/sbin:$PATH
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
ws=${NSCD_WS:-$repo/.build/ws}
out=$repo/build/mujoco_compare
quick=()
instructions=0
adaptive_dt=()
for a in "$@"; do
  case $a in
    --adaptive-dt=*) adaptive_dt=(--adaptive-dt "${a#*=}") ;;
    --quick) quick=(--quick) ;;
    --instructions) instructions=1 ;;
    -*) echo "usage: $0 [OUT_DIR] [--quick] [--instructions] [--adaptive-dt=S]" >&2; exit 2 ;;
    *) out=$a ;;
  esac
done
exe=$ws/devel/lib/nscd_sim/nscd_mujoco_compare
if [ ! -x "$exe" ]; then
  echo "no $exe: sudo apt-get install libmujoco-dev, then scripts/build.sh" >&2
  exit 1
fi
mkdir -p "$out"
rm -f "$out/instructions.csv" "$out/instructions_to_target.csv"
{
  echo "commit $(git -C "$repo" rev-parse --short HEAD)$( [ -z "$(git -C "$repo" status --porcelain --untracked-files=no)" ] || echo ' (with uncommitted changes)')"
  echo "date $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "mujoco $(dpkg-query -W -f='${Version}' libmujoco-dev 2>/dev/null || echo unknown)"
  echo "adaptive_dt ${adaptive_dt[1]:-0.01}"
  echo "load_start $(cut -d' ' -f1-3 /proc/loadavg)"
} > "$out/load.txt"
"$exe" --out "$out" "${quick[@]}" "${adaptive_dt[@]}"
echo "load_end $(cut -d' ' -f1-3 /proc/loadavg)" >> "$out/load.txt"

if [ "$instructions" = 1 ]; then
  echo "scene,method,steps,instructions" > "$out/instructions.csv"
  for scene in pendulum double_pendulum fourbar ball; do
    for method in nscd_fixed mujoco_euler mujoco_rk4; do
      case $method in
        nscd_*) fn='nscd::Simulator::step()' ;;
        *) fn='mj_step' ;;
      esac
      cg=$out/callgrind.$scene.$method
      valgrind --tool=callgrind --callgrind-out-file="$cg" --toggle-collect="$fn" \
        "$exe" --single "$scene" "$method" 1e-4 --steps 2000 > /dev/null 2>&1
      echo "$scene,$method,2000,$(sed -n 's/^totals: *//p' "$cg")" >> "$out/instructions.csv"
    done
  done
  # Whole runs at the key error (1e-4 rad at t = 1 s): each method's cheapest run at or below it.
  echo "scene,method,setting,instructions" > "$out/instructions_to_target.csv"
  /usr/bin/python3 "$repo/scripts/analysis/mujoco_compare.py" "$out" --pick | while read -r scene method setting; do
    case $method in
      nscd_*) fn='nscd::Simulator::step()' ;;
      *) fn='mj_step' ;;
    esac
    cg=$out/callgrind.whole.$scene.$method
    valgrind --tool=callgrind --callgrind-out-file="$cg" --toggle-collect="$fn" \
      "$exe" --single "$scene" "$method" "$setting" "${adaptive_dt[@]}" < /dev/null > /dev/null 2>&1
    echo "$scene,$method,$setting,$(sed -n 's/^totals: *//p' "$cg")" >> "$out/instructions_to_target.csv"
  done
fi
/usr/bin/python3 "$repo/scripts/analysis/mujoco_compare.py" "$out" | tee "$out/summary.md"
