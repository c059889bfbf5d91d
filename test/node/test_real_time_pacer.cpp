// The node's real-time pacing (src/node/real_time_pacer.*), on a fake clock:
// sim time advances real_time_factor seconds per wall second from the anchor, a
// step is due once its midpoint is, a backlog over 0.25 s of wall time is
// dropped, and real_time_factor 0 means no pacing.
#include <chrono>
#include <cmath>

#include <gtest/gtest.h>

#include "real_time_pacer.hpp"

using nscd_node::RealTimePacer;
using Clock = RealTimePacer::Clock;

namespace {
Clock::time_point at(double seconds) {
  return Clock::time_point(std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1000.0 + seconds)));
}
double secondsOf(Clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count() - 1000.0;
}
}  // namespace

TEST(RealTimePacer, StepLimitFollowsTheWallClock) {
  RealTimePacer p(0.5, 1e-3);  // half real time, 1 ms steps
  p.reanchor(at(0.0), 2.0);    // sim time 2 s reached at wall 0
  EXPECT_NEAR(p.stepLimit(at(0.0)), 2.0 - 0.5e-3, 1e-12);
  EXPECT_NEAR(p.stepLimit(at(0.1)), 2.05 - 0.5e-3, 1e-9);  // 0.1 s wall = 0.05 s sim
  EXPECT_TRUE(p.paced());
}

TEST(RealTimePacer, NextStepIsDueAtItsMidpoint) {
  RealTimePacer p(2.0, 1e-3);
  p.reanchor(at(0.0), 0.0);
  // From sim time 0.010 the step's midpoint 0.0105 is due at wall 0.0105 / 2.
  EXPECT_NEAR(secondsOf(p.nextStepDue(at(0.0), 0.010)), 0.00525, 1e-9);
}

TEST(RealTimePacer, BacklogOverAQuarterSecondIsDropped) {
  RealTimePacer p(1.0, 1e-3);
  p.reanchor(at(0.0), 0.0);
  EXPECT_FALSE(p.behind(at(0.2), 0.0));   // 0.2 s behind: catch up
  EXPECT_TRUE(p.behind(at(0.3), 0.0));    // 0.3 s behind: drop it
  EXPECT_FALSE(p.behind(at(0.3), 0.29));
  RealTimePacer slow(0.001, 1e-5);        // a C-60 trip shown at 1/1000
  slow.reanchor(at(0.0), 0.0);
  EXPECT_FALSE(slow.behind(at(0.2), 0.0));
  EXPECT_TRUE(slow.behind(at(0.3), 0.0));  // 0.3 ms of sim time = 0.3 s of wall time
}

TEST(RealTimePacer, ZeroFactorMeansAsFastAsPossible) {
  RealTimePacer p(0.0, 1e-3);
  p.reanchor(at(0.0), 0.0);
  EXPECT_FALSE(p.paced());
  EXPECT_TRUE(std::isinf(p.stepLimit(at(0.0))));
  EXPECT_FALSE(p.behind(at(100.0), 0.0));
  EXPECT_EQ(p.nextStepDue(at(5.0), 1.0), at(5.0));
}
