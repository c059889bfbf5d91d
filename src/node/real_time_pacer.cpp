// Real-time pacing of the node (real_time_pacer.hpp).
#include "real_time_pacer.hpp"

#include <cmath>

namespace nscd_node {
namespace {

double seconds(RealTimePacer::Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

void RealTimePacer::reanchor(Clock::time_point now, double sim_time) {
  anchor_wall_ = now;
  anchor_sim_ = sim_time;
}

double RealTimePacer::stepLimit(Clock::time_point now) const {
  if (!paced()) return INFINITY;
  return anchor_sim_ + rtf_ * seconds(now - anchor_wall_) - 0.5 * dt_;
}

bool RealTimePacer::behind(Clock::time_point now, double sim_time) const {
  if (!paced()) return false;
  const double target = anchor_sim_ + rtf_ * seconds(now - anchor_wall_);
  return (target - sim_time) / rtf_ > kMaxBacklog;
}

RealTimePacer::Clock::time_point RealTimePacer::nextStepDue(Clock::time_point now,
                                                            double sim_time) const {
  if (!paced()) return now;
  const double ahead = sim_time + 0.5 * dt_ - anchor_sim_;  // sim s past the anchor
  return anchor_wall_ + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(ahead / rtf_));
}

}  // namespace nscd_node
