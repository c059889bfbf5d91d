// The step loop every front end runs (nscd_run, nscd_sweep, the Python module,
// the work-precision tool): the commands of a step set from the schedules at its
// end, under either step control (Settings::step_control).
#pragma once

#include <vector>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd {

// Before step k (1, 2, ...): sets every scheduled actuator's command to its
// schedule's value at the end of the step and returns that time.
// Fixed steps: the end of step k is k dt (the rule of nscd_run).
// Adaptive steps: the step Simulator::planStep plans, cut so that it ends at
// `until` (the end of the run) and at the schedules' next corner (a time of a
// schedule point after the current time): a corner is never inside a step, so a
// step's linear command is the schedule's.
double prepareScheduledStep(Simulator& sim, const std::vector<BoundSchedule>& schedules, long k,
                            double until);

// The earliest time of a schedule point after t (+inf if none).
double nextScheduleCorner(const std::vector<BoundSchedule>& schedules, double t);

// Whether a run to `duration` is over after k steps: fixed, k reached round(duration
// / dt) (as nscd_run counts); adaptive, the sim time reached duration.
bool runFinished(const Simulator& sim, long k, double duration);

// Where a run of `duration` starts and ends, and how its fixed steps count time
// (nscd_run and nscd_sweep, from t = 0 or from a state file). From t = 0 step k
// ends at k dt. From a state at t0 that is a multiple of dt (to 1e-6 dt), K0 =
// round(t0 / dt), step k ends at (K0 + k) dt: the times of the run that wrote the
// state, so a continuation is bit-identical to it. From any other t0, at t0 + k dt.
// Adaptive steps run until t0 + duration.
class RunClock {
 public:
  RunClock(const Simulator& sim, double duration);

  double start() const { return t0_; }  // t0: the run's sim_time is t - t0

  // Sets the scheduled commands for step k (1, 2, ... of this run).
  void prepare(Simulator& sim, const std::vector<BoundSchedule>& schedules, long k) const;

  // Whether the run is over after k steps.
  bool finished(const Simulator& sim, long k) const;

 private:
  double t0_ = 0;
  double duration_ = 0;
  double until_ = 0;     // t0 + duration
  long first_step_ = 0;  // K0, or -1: t0 is not a multiple of dt
};

}  // namespace nscd
