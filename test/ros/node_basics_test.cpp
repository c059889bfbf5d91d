// rostest: tf for every link, actuator commands, malformed commands, ~reset and
// a failed step, on test/ros/actuated_pendulum.urdf (an arm on a vertical hinge).
#include <cmath>
#include <memory>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <std_srvs/Empty.h>
#include <std_srvs/SetBool.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/transform_listener.h>

#include "nscd_sim/ContactArray.h"
#include "nscd_sim/Step.h"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_test_support.hpp"

using nscd_test::nodeTopic;

namespace {

std::unique_ptr<tf2_ros::Buffer> g_tf;

// The first /tf transform of `child` stamped after `after` (null on timeout).
bool waitForTransform(const std::string& child, const ros::Time& after,
                      geometry_msgs::TransformStamped& out, double timeout = 5.0) {
  auto msg = nscd_test::waitForMessage<tf2_msgs::TFMessage>(
      "/tf",
      [&](const tf2_msgs::TFMessage& m) {
        for (const auto& t : m.transforms)
          if (t.child_frame_id == child && t.header.stamp > after) return true;
        return false;
      },
      timeout);
  if (!msg) return false;
  for (const auto& t : msg->transforms)
    if (t.child_frame_id == child) out = t;
  return true;
}

double armYaw() {
  geometry_msgs::TransformStamped t;
  if (!waitForTransform("arm", ros::Time::now(), t)) return NAN;
  return nscd_test::yawOf(t.transform.rotation);
}

void expectPoseEq(const geometry_msgs::Transform& t, const nscd::Pose& p, double tol) {
  EXPECT_NEAR(t.translation.x, p.p.x(), tol);
  EXPECT_NEAR(t.translation.y, p.p.y(), tol);
  EXPECT_NEAR(t.translation.z, p.p.z(), tol);
  // q and -q are the same rotation.
  const double dot = t.rotation.w * p.q.w() + t.rotation.x * p.q.x() +
                     t.rotation.y * p.q.y() + t.rotation.z * p.q.z();
  EXPECT_NEAR(std::abs(dot), 1.0, tol);
}

// The first /diagnostics message whose node status has `level` (null after 5 s).
diagnostic_msgs::DiagnosticArray::ConstPtr waitForDiagnosticLevel(uint8_t level) {
  return nscd_test::waitForMessage<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics",
      [level](const diagnostic_msgs::DiagnosticArray& m) {
        return !m.status.empty() && m.status[0].level == level;
      },
      5.0);
}

bool setPaused(bool paused) {
  std_srvs::SetBool srv;
  srv.request.data = paused;
  return nscd_test::callService(nodeTopic("pause"), srv) && srv.response.success;
}

}  // namespace

// Every link but the world frame appears in tf within a few seconds, at the
// pose the engine gives (the arm is at rest: no gravity torque, command 0).
TEST(NodeBasics, TransformForEveryLink) {
  const nscd::Model model = nscd::loadScene(nscd_test::sceneParam());
  nscd::Simulator sim(model);
  int checked = 0;
  for (size_t i = 0; i < model.links.size(); ++i) {
    const std::string& link = model.links[i].name;
    if (link == model.world_frame) continue;
    std::string err;
    ASSERT_TRUE(g_tf->canTransform(model.world_frame, link, ros::Time(0), ros::Duration(5.0), &err))
        << link << ": " << err;
    const auto t = g_tf->lookupTransform(model.world_frame, link, ros::Time(0));
    EXPECT_EQ(t.header.frame_id, model.world_frame);
    expectPoseEq(t.transform, sim.linkPose(static_cast<int>(i)), 1e-6);
    ++checked;
  }
  EXPECT_EQ(checked, 3);  // base, arm, tip
}

// A position command turns the arm toward the target and it settles there.
TEST(NodeBasics, CommandMovesJointTowardTarget) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Float64>(nodeTopic("hinge_motor/command"), 1);
  std_msgs::Float64 cmd;
  cmd.data = 0.6;
  ASSERT_TRUE(nscd_test::publishWhenConnected(pub, cmd));
  double yaw = armYaw();
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(8.0);
  double first_moved = NAN;
  while (ros::WallTime::now() < end && !(std::abs(yaw - 0.6) < 0.01)) {
    ros::WallDuration(0.05).sleep();
    yaw = armYaw();
    if (std::isnan(first_moved) && std::abs(yaw) > 1e-3) first_moved = yaw;
  }
  EXPECT_GT(first_moved, 0.0) << "the arm first moved away from the target";
  EXPECT_NEAR(yaw, 0.6, 0.01);
}

// NaN and infinite commands, and a command on a topic with no actuator, are
// ignored: the node keeps running and the arm keeps the last good target.
TEST(NodeBasics, MalformedCommandIsIgnored) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Float64>(nodeTopic("hinge_motor/command"), 3);
  ros::Publisher unknown = nh.advertise<std_msgs::Float64>(nodeTopic("no_such/command"), 1);
  std_msgs::Float64 cmd;
  cmd.data = NAN;
  ASSERT_TRUE(nscd_test::publishWhenConnected(pub, cmd));
  ros::WallDuration(0.05).sleep();
  cmd.data = INFINITY;
  pub.publish(cmd);
  ros::WallDuration(0.05).sleep();
  cmd.data = -INFINITY;
  pub.publish(cmd);
  cmd.data = 3.0;
  unknown.publish(cmd);
  ros::WallDuration(1.0).sleep();

  EXPECT_NEAR(armYaw(), 0.6, 0.01);
  std_srvs::SetBool srv;  // still serving
  srv.request.data = false;
  EXPECT_TRUE(nscd_test::callService(nodeTopic("pause"), srv, 2.0));
}

// ~reset brings every link back to the initial pose, sim time to 0 and the
// actuator command to its initial value.
TEST(NodeBasics, ResetRestoresInitialPose) {
  const nscd::Model model = nscd::loadScene(nscd_test::sceneParam());
  nscd::Simulator sim(model);
  ASSERT_GT(std::abs(armYaw()), 0.5) << "the arm should have moved before the reset";

  ASSERT_TRUE(setPaused(true));
  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("reset"), reset));
  const ros::Time after = ros::Time::now();
  for (size_t i = 0; i < model.links.size(); ++i) {
    if (model.links[i].name == model.world_frame) continue;
    geometry_msgs::TransformStamped t;
    ASSERT_TRUE(waitForTransform(model.links[i].name, after, t)) << model.links[i].name;
    expectPoseEq(t.transform, sim.linkPose(static_cast<int>(i)), 1e-12);
  }
  auto contacts = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"),
      [&](const nscd_sim::ContactArray& m) { return m.header.stamp > after; }, 5.0);
  ASSERT_TRUE(contacts);
  EXPECT_EQ(contacts->sim_time, 0.0);
  EXPECT_EQ(contacts->steps, 0u);

  // The command went back to its initial value 0: resumed, the arm stays put.
  ASSERT_TRUE(setPaused(false));
  ros::WallDuration(0.5).sleep();
  EXPECT_NEAR(armYaw(), 0.0, 1e-6);
}

// A step that fails (a force of 1e308 N overflows the state) is reported on
// /diagnostics as an ERROR with its time, stops stepping, and ~reset recovers.
TEST(NodeBasics, FailedStepPausesUntilReset) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Float64>(nodeTopic("push/command"), 1);
  std_msgs::Float64 cmd;
  cmd.data = 1e308;
  ASSERT_TRUE(nscd_test::publishWhenConnected(pub, cmd));

  using diagnostic_msgs::DiagnosticStatus;
  auto error = waitForDiagnosticLevel(DiagnosticStatus::ERROR);
  ASSERT_TRUE(error);
  EXPECT_NE(error->status[0].message.find("step failed at t="), std::string::npos)
      << error->status[0].message;

  nscd_sim::Step step;  // stepping stays blocked until the reset
  step.request.count = 1;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("step"), step));
  EXPECT_FALSE(step.response.success);
  EXPECT_EQ(step.response.steps_taken, 0u);

  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("reset"), reset));
  auto ok = waitForDiagnosticLevel(DiagnosticStatus::OK);
  ASSERT_TRUE(ok);
  auto later = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"), [](const nscd_sim::ContactArray& m) { return m.sim_time > 0.2; },
      5.0);
  EXPECT_TRUE(later) << "stepping did not resume after ~reset";
  EXPECT_NEAR(armYaw(), 0.0, 1e-6);
}

int main(int argc, char** argv) {
  return nscd_test::runRosTestNode(argc, argv, "node_basics_test", [] {
    g_tf = std::make_unique<tf2_ros::Buffer>();
    tf2_ros::TransformListener listener(*g_tf);
    return RUN_ALL_TESTS();
  });
}
