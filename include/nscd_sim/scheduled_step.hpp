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

}  // namespace nscd
