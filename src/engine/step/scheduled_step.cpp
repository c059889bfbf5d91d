// The step loop of the front ends (scheduled_step.hpp).
#include "nscd_sim/scheduled_step.hpp"

#include <algorithm>
#include <cmath>

namespace nscd {

double nextScheduleCorner(const std::vector<BoundSchedule>& schedules, double t) {
  double corner = INFINITY;
  for (const BoundSchedule& b : schedules)
    for (const auto& point : b.schedule.points)
      if (point.first > t) {
        corner = std::min(corner, point.first);
        break;  // times are non-decreasing
      }
  return corner;
}

double prepareScheduledStep(Simulator& sim, const std::vector<BoundSchedule>& schedules, long k,
                            double until) {
  double end = 0;
  if (sim.model().settings.step_control == StepControl::Adaptive)
    end = sim.planStep(std::min(until, nextScheduleCorner(schedules, sim.state().t)));
  else
    end = k * sim.model().settings.dt;
  applySchedules(schedules, end, sim);
  return end;
}

bool runFinished(const Simulator& sim, long k, double duration) {
  if (sim.model().settings.step_control == StepControl::Adaptive) return !(sim.state().t < duration);
  return k >= std::llround(duration / sim.model().settings.dt);
}

}  // namespace nscd
