// rostest: use_sim_time conventions (/clock, tf stamped with sim time), ~pause
// stops time, /diagnostics carries the solver statistics. The node reads its
// scene from robot_description. Waits are in wall time: this test node's own
// ros::Time follows /clock.
#include <algorithm>
#include <cmath>
#include <map>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>

#include "nscd_sim/Step.h"
#include "ros_test_support.hpp"

using nscd_test::nodeTopic;

namespace {

double clockNow() {
  auto c = nscd_test::waitForMessage<rosgraph_msgs::Clock>("/clock", 5.0);
  return c ? c->clock.toSec() : NAN;
}

bool setPaused(bool paused) {
  std_srvs::SetBool srv;
  srv.request.data = paused;
  return nscd_test::callService(nodeTopic("pause"), srv) && srv.response.success;
}

std::map<std::string, std::string> diagnosticValues(const diagnostic_msgs::DiagnosticStatus& s) {
  std::map<std::string, std::string> v;
  for (const auto& kv : s.values) v[kv.key] = kv.value;
  return v;
}

}  // namespace

// /clock is published and advances at about the requested real-time factor 1
// (at least a quarter of it on a loaded machine, never much faster).
TEST(SimTime, ClockAdvances) {
  const double c0 = clockNow();
  const ros::WallTime w0 = ros::WallTime::now();
  ros::WallDuration(1.0).sleep();
  const double c1 = clockNow();
  const double wall = (ros::WallTime::now() - w0).toSec();
  ASSERT_TRUE(std::isfinite(c0) && std::isfinite(c1));
  EXPECT_GT(c1 - c0, 0.25 * wall);
  EXPECT_LT(c1 - c0, 1.2 * wall + 0.1);
}

// tf is stamped with sim time (seconds since the start, not the wall epoch).
TEST(SimTime, TransformsStampedWithSimTime) {
  auto tf = nscd_test::waitForMessage<tf2_msgs::TFMessage>(
      "/tf", [](const tf2_msgs::TFMessage& m) { return !m.transforms.empty(); }, 5.0);
  ASSERT_TRUE(tf);
  const double stamp = tf->transforms[0].header.stamp.toSec();
  EXPECT_GT(stamp, 0.0);
  EXPECT_LT(stamp, clockNow() + 1e-9);
  EXPECT_LT(stamp, 1e6);  // not wall time
}

// ~pause(true) stops /clock; ~pause(false) lets it run again.
TEST(SimTime, PauseStopsTime) {
  ASSERT_TRUE(setPaused(true));
  ros::WallDuration(0.1).sleep();
  const double c0 = clockNow();
  ros::WallDuration(0.6).sleep();
  const double c1 = clockNow();
  EXPECT_EQ(c0, c1);

  // Paused, tf is not repeated, but a listener that connects now (RViz started
  // late) still gets the transforms, stamped with the paused time.
  auto tf = nscd_test::waitForMessage<tf2_msgs::TFMessage>("/tf", 2.0);
  ASSERT_TRUE(tf);
  ASSERT_FALSE(tf->transforms.empty());
  EXPECT_NEAR(tf->transforms[0].header.stamp.toSec(), c1, 1e-6);

  // Paused, ~step N moves /clock by exactly N steps (dt = 1 ms in this scene).
  nscd_sim::Step step;
  step.request.count = 100;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("step"), step));
  ASSERT_TRUE(step.response.success);
  EXPECT_NEAR(step.response.sim_time, c1 + 0.1, 1e-9);
  auto clock = nscd_test::waitForMessage<rosgraph_msgs::Clock>(
      "/clock", [&](const rosgraph_msgs::Clock& c) { return c.clock.toSec() > c1; }, 5.0);
  ASSERT_TRUE(clock);
  EXPECT_NEAR(clock->clock.toSec(), step.response.sim_time, 1e-9);

  ASSERT_TRUE(setPaused(false));
  auto running = nscd_test::waitForMessage<rosgraph_msgs::Clock>(
      "/clock",
      [&](const rosgraph_msgs::Clock& c) { return c.clock.toSec() > step.response.sim_time; },
      10.0);
  EXPECT_TRUE(running) << "/clock did not move after ~pause(false)";
}

// /diagnostics: one status for the simulator, level OK, with the solver and
// pacing statistics; "paused" while paused.
TEST(SimTime, DiagnosticsReportSolverStatistics) {
  using diagnostic_msgs::DiagnosticArray;
  auto diag = nscd_test::waitForMessage<DiagnosticArray>(
      "/diagnostics",
      [](const DiagnosticArray& m) {
        return !m.status.empty() && m.status[0].name == "nscd_sim: simulator" &&
               m.status[0].message == "running";
      },
      5.0);
  ASSERT_TRUE(diag);
  const auto& s = diag->status[0];
  EXPECT_EQ(s.level, diagnostic_msgs::DiagnosticStatus::OK);
  auto v = diagnosticValues(s);
  for (const char* key : {"sim_time", "steps", "rtf", "publish_rate", "iterations", "residual",
                          "active_contacts", "unconverged_steps", "halved_steps", "step_failures"})
    EXPECT_TRUE(v.count(key)) << key;
  EXPECT_GT(std::stod(v["rtf"]), 0.25);
  EXPECT_GT(std::stod(v["publish_rate"]), 10.0);
  EXPECT_EQ(v["step_failures"], "0");

  ASSERT_TRUE(setPaused(true));
  auto paused = nscd_test::waitForMessage<DiagnosticArray>(
      "/diagnostics",
      [](const DiagnosticArray& m) { return !m.status.empty() && m.status[0].message == "paused"; },
      5.0);
  ASSERT_TRUE(paused);
  EXPECT_EQ(diagnosticValues(paused->status[0])["paused"], "true");
  ASSERT_TRUE(setPaused(false));
}

int main(int argc, char** argv) { return nscd_test::runRosTestNode(argc, argv, "sim_time_test"); }
