// The actuator handles of nscd_actuator_markers (src/node/actuator_handle.*), ROS-free:
// where each marker stands and which command a dragged pose asks for, on the C-60
// (handle on J1, probe along its bore) and on a small scene with a slide and a turn
// about a joint whose parent moves.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "actuator_handle.hpp"
#include "nscd_sim/scene_loader.hpp"

using nscd_node::ActuatorHandle;
using nscd_node::actuatorHandle;

namespace {

const nscd::Model& c60() {
  static const nscd::Model m = nscd::loadScene(std::string(NSCD_SOURCE_DIR) + "/urdf/c60.urdf");
  return m;
}

// A carriage on a rail (prescribed along x) carrying an arm on a hinge turned 0.5 rad
// about z at its URDF zero.
const char* const kCarriage = R"(<?xml version="1.0"?>
<robot name="carriage">
  <link name="world"/>
  <link name="carriage">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="rail" type="prismatic">
    <parent link="world"/><child link="carriage"/>
    <origin xyz="0.1 0.2 0"/><axis xyz="1 0 0"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
  <link name="arm">
    <inertial><origin xyz="0.3 0 0"/><mass value="1"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="elbow" type="continuous">
    <parent link="carriage"/><child link="arm"/>
    <origin xyz="0 0 0.05" rpy="0 0 0.5"/><axis xyz="0 0 1"/>
  </joint>
  <nscd><actuator name="slide" type="prescribed" joint="rail"/></nscd>
  <nscd><actuator name="turn" type="position" joint="elbow" kp="1" kd="0.1"/></nscd>
  <nscd><actuator name="push" type="force" link="arm" xyz="0.3 0 0" direction="0 1 0"/></nscd>
</robot>)";

void expectNear(const nscd::Vec3& a, const nscd::Vec3& b, double tol, const char* what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": (" << a.transpose() << ") vs (" << b.transpose() << ")";
}

}  // namespace

// The handle turns about J1 (world z through the pin of the case): the marker at the
// pivot, x along the axis, the lever towards the handle's centre of mass at command 0;
// a pose turned by a about the axis asks for command a, also past half a turn.
TEST(ActuatorHandle, C60HandleTurnsAboutJ1) {
  const nscd::Model& m = c60();
  const ActuatorHandle h = actuatorHandle(m, "handle");
  EXPECT_EQ(h.motion, ActuatorHandle::Motion::Rotate);
  EXPECT_EQ(h.frame, m.world_frame);
  expectNear(h.origin, nscd::Vec3(-0.0161, 0.01, 0.00555), 1e-12, "pivot (J1's origin)");
  expectNear(h.axis, nscd::Vec3::UnitZ(), 1e-12, "axis");
  expectNear(h.zero * nscd::Vec3::UnitX(), h.axis, 1e-12, "marker x");
  const nscd::Body& handle = m.bodies[m.findBody("handle")];
  nscd::Vec3 lever = handle.initial_pose.p - h.origin;
  lever.z() = 0;
  EXPECT_NEAR(h.lever, lever.norm(), 1e-12);
  expectNear(h.zero * nscd::Vec3::UnitY(), lever.normalized(), 1e-9, "lever at command 0");

  for (double a : {0.0, 0.3, 1.2, -0.4, 3.0}) {
    const nscd::Pose p = h.poseAt(a);
    expectNear(p.p, h.origin, 1e-15, "the pivot stays");
    EXPECT_NEAR(h.commandAt(p, a), a, 1e-12) << "round trip at " << a;
  }
  // The lever turns with the command, anticlockwise seen from +z for a positive one.
  const nscd::Vec3 y0 = h.poseAt(0).q * nscd::Vec3::UnitY();
  const nscd::Vec3 y1 = h.poseAt(1.2).q * nscd::Vec3::UnitY();
  EXPECT_NEAR(std::atan2(y0.cross(y1).z(), y0.dot(y1)), 1.2, 1e-12);
  // Past half a turn: the turn nearest the previous command.
  EXPECT_NEAR(h.commandAt(h.poseAt(3.5), 3.0), 3.5, 1e-12);
  EXPECT_NEAR(h.commandAt(h.poseAt(3.5), 0.0), 3.5 - 2 * M_PI, 1e-12);
  // A tilt off the axis (RViz never sends one for ROTATE_AXIS) is ignored.
  nscd::Pose tilted = h.poseAt(0.7);
  tilted.q = nscd::Quat(Eigen::AngleAxisd(0.7, nscd::Vec3::UnitZ())) *
             nscd::Quat(Eigen::AngleAxisd(1e-3, nscd::Vec3::UnitX())) * h.zero;
  EXPECT_NEAR(h.commandAt(tilted, 0.7), 0.7, 1e-6);
}

// The probe slides along world +x (its axis -1 0 0 in its own, flipped frame): the
// marker at the probe's centre of mass plus the command along the axis.
TEST(ActuatorHandle, C60ProbeSlidesAlongItsBore) {
  const nscd::Model& m = c60();
  const ActuatorHandle h = actuatorHandle(m, "probe");
  EXPECT_EQ(h.motion, ActuatorHandle::Motion::Slide);
  EXPECT_EQ(h.frame, m.world_frame);
  expectNear(h.axis, nscd::Vec3::UnitX(), 1e-9, "axis");
  expectNear(h.origin, m.bodies[m.findBody("probe")].initial_pose.p, 1e-15, "origin");
  expectNear(h.zero * nscd::Vec3::UnitX(), h.axis, 1e-12, "marker x");
  for (double c : {0.0, 0.0015, 0.004, -0.001}) {
    const nscd::Pose p = h.poseAt(c);
    expectNear(p.p, h.origin + c * h.axis, 1e-15, "position");
    EXPECT_NEAR(h.commandAt(p), c, 1e-15);
  }
  // Only the part along the axis counts.
  nscd::Pose off = h.poseAt(0.002);
  off.p += nscd::Vec3(0, 0.003, -0.001);
  EXPECT_NEAR(h.commandAt(off), 0.002, 1e-15);
}

// A joint whose parent moves: the marker rides in the parent's link frame.
TEST(ActuatorHandle, JointOnAMovingParent) {
  const nscd::Model m = nscd::loadSceneFromString(kCarriage, "carriage.urdf");
  const ActuatorHandle turn = actuatorHandle(m, "turn");
  EXPECT_EQ(turn.motion, ActuatorHandle::Motion::Rotate);
  EXPECT_EQ(turn.frame, "carriage");
  expectNear(turn.origin, nscd::Vec3(0, 0, 0.05), 1e-12, "pivot in the carriage's frame");
  expectNear(turn.axis, nscd::Vec3::UnitZ(), 1e-12, "axis");
  EXPECT_NEAR(turn.lever, 0.3, 1e-12);
  expectNear(turn.zero * nscd::Vec3::UnitY(), nscd::Vec3(std::cos(0.5), std::sin(0.5), 0), 1e-12,
             "lever at the URDF zero");
  EXPECT_NEAR(turn.commandAt(turn.poseAt(-0.8), -0.8), -0.8, 1e-12);

  const ActuatorHandle slide = actuatorHandle(m, "slide");
  EXPECT_EQ(slide.motion, ActuatorHandle::Motion::Slide);
  EXPECT_EQ(slide.frame, "world");
  expectNear(slide.origin, nscd::Vec3(0.1, 0.2, 0), 1e-12, "rail origin");
  expectNear(slide.axis, nscd::Vec3::UnitX(), 1e-12, "rail axis");
  EXPECT_NEAR(slide.commandAt(slide.poseAt(0.25)), 0.25, 1e-15);
}

// Nothing to grab on a force or torque actuator; an unknown name lists the actuators.
TEST(ActuatorHandle, RefusesWhatItCannotDrive) {
  try {
    actuatorHandle(c60(), "bar_seating");
    FAIL() << "a torque actuator got a handle";
  } catch (const nscd::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("'bar_seating' is a torque actuator"), std::string::npos) << e.what();
  }
  try {
    actuatorHandle(c60(), "handel");
    FAIL() << "an unknown actuator got a handle";
  } catch (const nscd::SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("no actuator 'handel'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("handle, probe, bar_seating"), std::string::npos) << e.what();
  }
}

TEST(ActuatorHandle, RangeClips) {
  const nscd_node::CommandRange r{0.0, 1.3};
  EXPECT_EQ(r.clip(-0.2), 0.0);
  EXPECT_EQ(r.clip(0.7), 0.7);
  EXPECT_EQ(r.clip(2.0), 1.3);
  EXPECT_TRUE(r.contains(1.3));
  EXPECT_FALSE(r.contains(1.3000001));
}
