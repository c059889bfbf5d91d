# Sourced after scripts/c60_env.sh: the C-60's solver scenarios, shared by
# scripts/c60_solver_bench.sh and bench/solver_stages.sh. Scenarios: rest (100 ms);
# trip (the probe at 0.2 m/s from 0.7 ms, 20.7 ms); bench (the table schedule, 54 ms);
# handle (ON -> towards OFF and back, 40 ms). Models: paper (urdf/c60.urdf,
# c60_bench.urdf) and ideal (c60_ideal.urdf, c60_bench_ideal.urdf).
C60_SCENARIOS="rest trip bench handle"
C60_MODELS="paper ideal"
C60_HANDLE="handle=0:0,0.004:0,0.014:1.2,0.020:1.2,0.030:0,0.040:0"
# c60_scenario_args SCENARIO MODEL: sets the array c60_args to nscd_run's scene and
# options for that run (all but --dt and the output options).
c60_scenario_args() {
  local sfx=""
  [ "$2" = ideal ] && sfx="_ideal"
  case $1 in
    rest) c60_args=("$C60_REPO/urdf/c60$sfx.urdf" --duration 0.1) ;;
    trip) c60_args=("$C60_REPO/urdf/c60$sfx.urdf" --duration 0.0207 --command "$C60_PROBE") ;;
    bench) c60_args=("$C60_REPO/urdf/c60_bench$sfx.urdf" --duration 0.054 --command "$C60_TABLE") ;;
    handle) c60_args=("$C60_REPO/urdf/c60$sfx.urdf" --duration 0.040 --command "$C60_HANDLE") ;;
    *) echo "c60_scenario_args: no scenario $1" >&2; return 1 ;;
  esac
}
