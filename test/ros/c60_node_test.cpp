// rostest: nscd_sim_node runs the C-60 breaker (urdf/c60.urdf).
// c60_node.test: it rests latched and ~handle/command (towards OFF) opens the
// contacts. c60_trip.test: the ~schedule parameter drives the probe (the trip
// scenario of scripts/c60_trip.sh) and the breaker trips in the same window as
// nscd_run (C7 opens at 7.46 ms there).
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_msgs/Float64.h>
#include <tf2_msgs/TFMessage.h>

#include "nscd_sim/ContactArray.h"
#include "ros_test_support.hpp"

using nscd_test::nodeTopic;

namespace {

// The summed normal force of the named contact (0 if it is not active).
double normalForce(const nscd_sim::ContactArray& m, const std::string& name) {
  double f = 0;
  for (const auto& c : m.contacts)
    if (c.name == name) f += c.normal_force;
  return f;
}

bool hasContact(const nscd_sim::ContactArray& m, const std::string& name) {
  for (const auto& c : m.contacts)
    if (c.name == name) return true;
  return false;
}

nscd_sim::ContactArrayConstPtr contactsAfter(double sim_time, double timeout) {
  return nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"),
      [&](const nscd_sim::ContactArray& m) { return m.sim_time >= sim_time; }, timeout);
}

// Rotation of the handle about the breaker's axis (z), from /tf.
double handleAngle(double timeout = 10.0) {
  auto msg = nscd_test::waitForMessage<tf2_msgs::TFMessage>(
      "/tf",
      [](const tf2_msgs::TFMessage& m) {
        for (const auto& t : m.transforms)
          if (t.child_frame_id == "handle") return true;
        return false;
      },
      timeout);
  if (!msg) return NAN;
  for (const auto& t : msg->transforms)
    if (t.child_frame_id == "handle") return nscd_test::yawOf(t.transform.rotation);
  return NAN;
}

}  // namespace

// ON and latched: C7 carries the contact pressure (13.4 N in nscd_run), the
// latch C4 holds. Then handle -> +1.2 rad: the toggle passes dead centre and C7
// opens (nscd_run: within 3 ms of a step command).
TEST(C60Node, RestsLatchedAndHandleCommandOpensContacts) {
  auto on = contactsAfter(0.002, 60.0);
  ASSERT_TRUE(on) << "no ~contacts with sim_time >= 2 ms";
  EXPECT_GT(normalForce(*on, "C7"), 10.0) << "contact pressure at rest";
  EXPECT_LT(normalForce(*on, "C7"), 20.0);
  EXPECT_TRUE(hasContact(*on, "C4")) << "latch C4 not closed at rest";
  const double angle0 = handleAngle();
  ASSERT_TRUE(std::isfinite(angle0));

  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<std_msgs::Float64>(nodeTopic("handle/command"), 1);
  std_msgs::Float64 cmd;
  cmd.data = 1.2;
  auto before = contactsAfter(0.0, 10.0);
  ASSERT_TRUE(before);
  ASSERT_TRUE(nscd_test::publishWhenConnected(pub, cmd));
  const double t_cmd = before->sim_time;

  // Opened: no C7 point, well after the command (10 ms of sim time at most).
  auto open = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"),
      [&](const nscd_sim::ContactArray& m) { return m.sim_time > t_cmd && !hasContact(m, "C7"); },
      120.0);
  ASSERT_TRUE(open) << "the contacts did not open after the handle command";
  EXPECT_LT(open->sim_time - t_cmd, 0.012) << "opened too late";
  auto later = contactsAfter(open->sim_time + 0.003, 60.0);
  ASSERT_TRUE(later);
  EXPECT_FALSE(hasContact(*later, "C7")) << "C7 closed again with the handle held OFF";
  const double angle1 = handleAngle();
  EXPECT_GT(angle1 - angle0, 0.5) << "handle did not turn towards OFF";
}

// ~schedule: probe still until 0.7 ms, then 0.2 m/s. The latch holds before the
// probe arrives and the contacts open between 6 and 9 ms (nscd_run: 7.46 ms).
TEST(C60Node, ProbeScheduleTripsTheBreaker) {
  auto early = contactsAfter(0.003, 60.0);
  ASSERT_TRUE(early);
  ASSERT_LT(early->sim_time, 0.006) << "publishing too sparse to see the closed state";
  EXPECT_GT(normalForce(*early, "C7"), 10.0) << "opened before the probe arrived";
  auto open = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"),
      [&](const nscd_sim::ContactArray& m) { return m.sim_time > 0.003 && !hasContact(m, "C7"); },
      120.0);
  ASSERT_TRUE(open) << "the breaker did not trip";
  EXPECT_GT(open->sim_time, 0.006);
  EXPECT_LT(open->sim_time, 0.009);
}

int main(int argc, char** argv) { return nscd_test::runRosTestNode(argc, argv, "c60_node_test"); }
