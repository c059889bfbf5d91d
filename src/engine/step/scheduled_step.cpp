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

namespace {

// The schedule's value just after t: at a time listed more than once (a jump)
// the last value listed there, elsewhere value(t) (which takes the first one).
double valueAfter(const CommandSchedule& s, double t) {
  for (auto p = s.points.rbegin(); p != s.points.rend(); ++p)
    if (p->first == t) return p->second;
  return s.value(t);
}

}  // namespace

double prepareScheduledStep(Simulator& sim, const std::vector<BoundSchedule>& schedules, long k,
                            double until) {
  double end = 0;
  if (sim.model().settings.step_control == StepControl::Adaptive) {
    // The step starts from the schedules' values just after its start (a jump at
    // the start is taken at once, as a fixed step takes it), and is planned
    // (which keeps them) to end at the next corner at the latest.
    const double t = sim.state().t;
    for (const BoundSchedule& b : schedules) sim.setCommand(b.actuator, valueAfter(b.schedule, t));
    end = sim.planStep(std::min(until, nextScheduleCorner(schedules, t)));
  } else {
    end = k * sim.model().settings.dt;
  }
  applySchedules(schedules, end, sim);
  return end;
}

bool runFinished(const Simulator& sim, long k, double duration) {
  if (sim.model().settings.step_control == StepControl::Adaptive) return !(sim.state().t < duration);
  return k >= std::llround(duration / sim.model().settings.dt);
}

RunClock::RunClock(const Simulator& sim, double duration)
    : t0_(sim.state().t), duration_(duration), until_(t0_ + duration) {
  const double dt = sim.model().settings.dt;
  const double k0 = std::round(t0_ / dt);
  first_step_ = std::abs(t0_ / dt - k0) <= 1e-6 ? static_cast<long>(k0) : -1;
}

void RunClock::prepare(Simulator& sim, const std::vector<BoundSchedule>& schedules, long k) const {
  if (sim.model().settings.step_control == StepControl::Fixed && first_step_ < 0)
    applySchedules(schedules, t0_ + k * sim.model().settings.dt, sim);
  else
    prepareScheduledStep(sim, schedules, first_step_ + k, until_);
}

bool RunClock::finished(const Simulator& sim, long k) const {
  const bool adaptive = sim.model().settings.step_control == StepControl::Adaptive;
  return runFinished(sim, k, adaptive ? until_ : duration_);
}

}  // namespace nscd
