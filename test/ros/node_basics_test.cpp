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

std::unique_ptr<nscd_test::SteppedNode> g_node;

double armYaw() { return g_node->yaw("arm"); }

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

}  // namespace

// The node starts paused (node_basics.test) and every test drives it with ~step,
// so what it checks happens at a fixed sim time whatever the machine's load.

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

// A position command turns the arm toward the target, and within 8 s of sim
// time (kp 20, kd 2.5: about 2 s time constant) it settles there. The same
// steps in an in-process simulator give the same angle.
TEST(NodeBasics, CommandMovesJointTowardTarget) {
  ASSERT_TRUE(g_node->command("hinge_motor", 0.6));
  nscd::Simulator sim(nscd::loadScene(nscd_test::sceneParam()));
  sim.setCommand(0, 0.6);
  double first_moved = NAN;
  for (int chunk = 0; chunk < 32; ++chunk) {  // 32 x 250 steps of 1 ms
    ASSERT_TRUE(g_node->step(250)) << "chunk " << chunk;
    const double yaw = armYaw();
    if (std::isnan(first_moved) && std::abs(yaw) > 1e-3) first_moved = yaw;
  }
  for (int i = 0; i < 8000; ++i) sim.step();
  EXPECT_GT(first_moved, 0.0) << "the arm first moved away from the target";
  EXPECT_NEAR(armYaw(), 0.6, 0.01);
  int arm_link = -1;
  for (size_t i = 0; i < sim.model().links.size(); ++i)
    if (sim.model().links[i].name == "arm") arm_link = static_cast<int>(i);
  ASSERT_GE(arm_link, 0);
  const nscd::Pose arm = sim.linkPose(arm_link);
  EXPECT_NEAR(armYaw(), 2.0 * std::atan2(arm.q.z(), arm.q.w()), 1e-9) << "node != engine";
}

// NaN and infinite commands, and a command on a topic with no actuator, are
// ignored: the node keeps stepping and the arm keeps the last good target.
TEST(NodeBasics, MalformedCommandIsIgnored) {
  g_node->publishCommand("hinge_motor", NAN);
  g_node->publishCommand("hinge_motor", INFINITY);
  g_node->publishCommand("hinge_motor", -INFINITY);
  ros::NodeHandle nh;  // nobody subscribes to it: publish without waiting
  ros::Publisher unknown = nh.advertise<std_msgs::Float64>(nodeTopic("no_such/command"), 1);
  std_msgs::Float64 three;
  three.data = 3.0;
  unknown.publish(three);
  // Same publisher, same connection: these land in order, after the bad ones.
  ASSERT_TRUE(g_node->command("hinge_motor", 0.61));
  ASSERT_TRUE(g_node->step(1000)) << "a bad command broke stepping";
  EXPECT_NEAR(armYaw(), 0.6, 0.015);
  EXPECT_EQ(g_node->keyFigure("hinge_motor.cmd"), 0.61);
}

// ~reset brings every link back to the initial pose, sim time to 0 and the
// actuator command to its initial value.
TEST(NodeBasics, ResetRestoresInitialPose) {
  const nscd::Model model = nscd::loadScene(nscd_test::sceneParam());
  nscd::Simulator sim(model);
  ASSERT_GT(std::abs(armYaw()), 0.5) << "the arm should have moved before the reset";

  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("reset"), reset));
  auto contacts = g_node->waitForContacts(
      [](const nscd_sim::ContactArray& m) { return m.steps == 0; }, 5.0);
  ASSERT_TRUE(contacts);
  EXPECT_EQ(contacts->sim_time, 0.0);
  for (size_t i = 0; i < model.links.size(); ++i) {
    if (model.links[i].name == model.world_frame) continue;
    geometry_msgs::TransformStamped t;
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(5.0);
    while (ros::WallTime::now() < end &&
           !(g_node->transform(model.links[i].name, t) && t.header.stamp >= contacts->header.stamp))
      ros::WallDuration(0.002).sleep();
    ASSERT_GE(t.header.stamp, contacts->header.stamp) << model.links[i].name;
    expectPoseEq(t.transform, sim.linkPose(static_cast<int>(i)), 1e-12);
  }
  // The command went back to its initial value 0: stepped, the arm stays put.
  ASSERT_TRUE(g_node->step(500));
  EXPECT_EQ(g_node->keyFigure("hinge_motor.cmd"), 0.0);
  EXPECT_NEAR(armYaw(), 0.0, 1e-6);
}

// A step that fails (a force of 1e308 N overflows the state) is reported on
// /diagnostics as an ERROR with its time, stops stepping, and ~reset recovers.
TEST(NodeBasics, FailedStepPausesUntilReset) {
  ASSERT_TRUE(g_node->command("push", 1e308));
  EXPECT_FALSE(g_node->step(1)) << "the overflowing step should fail";
  EXPECT_FALSE(g_node->lastStepSucceeded());

  using diagnostic_msgs::DiagnosticStatus;
  auto error = waitForDiagnosticLevel(DiagnosticStatus::ERROR);
  ASSERT_TRUE(error);
  EXPECT_NE(error->status[0].message.find("step failed at t="), std::string::npos)
      << error->status[0].message;

  EXPECT_FALSE(g_node->step(1)) << "stepping stays blocked until the reset";
  EXPECT_EQ(g_node->lastStepsTaken(), 0u);

  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("reset"), reset));
  auto ok = waitForDiagnosticLevel(DiagnosticStatus::OK);
  ASSERT_TRUE(ok);
  ASSERT_TRUE(g_node->step(200)) << "stepping did not resume after ~reset";
  EXPECT_NEAR(armYaw(), 0.0, 1e-6);
}

int main(int argc, char** argv) {
  return nscd_test::runRosTestNode(argc, argv, "node_basics_test", [] {
    g_tf = std::make_unique<tf2_ros::Buffer>();
    tf2_ros::TransformListener listener(*g_tf);
    g_node = std::make_unique<nscd_test::SteppedNode>();
    const int result = RUN_ALL_TESTS();
    g_node.reset();
    return result;
  });
}
