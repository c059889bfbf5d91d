// Pacing of the node's stepping against the wall clock, ROS-free (tested alone):
// sim time should advance real_time_factor seconds per wall second from an
// anchor (sim time t0 at wall time w0). A backlog the engine cannot catch up is
// dropped (the anchor moves) rather than run off later in a burst.
#pragma once

#include <chrono>

namespace nscd_node {

class RealTimePacer {
 public:
  using Clock = std::chrono::steady_clock;

  // real_time_factor: sim seconds per wall second, 0 = as fast as possible.
  RealTimePacer(double real_time_factor, double dt) : rtf_(real_time_factor), dt_(dt) {}

  // Sim time `sim_time` is reached at wall time `now` (start, resume, reset, step).
  void reanchor(Clock::time_point now, double sim_time);

  // Step while the sim time is below this (the wall clock's sim time less half a
  // step, so a step is taken once its midpoint is due); +inf without pacing.
  double stepLimit(Clock::time_point now) const;

  // The simulation lags the wall clock by more than the dropped backlog (0.25 s
  // of wall time): reanchor. Never with pacing off.
  bool behind(Clock::time_point now, double sim_time) const;

  // Wall time at which the step from `sim_time` is due (now, without pacing).
  Clock::time_point nextStepDue(Clock::time_point now, double sim_time) const;

  bool paced() const { return rtf_ > 0; }

  // Wall seconds of backlog dropped (see behind).
  static constexpr double kMaxBacklog = 0.25;

 private:
  double rtf_, dt_;
  Clock::time_point anchor_wall_;
  double anchor_sim_ = 0;
};

}  // namespace nscd_node
