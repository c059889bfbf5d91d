// Scene loader: the demo scenes give the Model they should (exact values computed by
// hand), every bad scene is refused with "FILE:LINE: what", and settings overrides work.
#include <dirent.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "nscd_sim/scene_loader.hpp"
#include "test_support.hpp"

using namespace nscd;
using nscd_test::scenePath;

namespace {

constexpr double kTight = 1e-12;
const double kPi = std::acos(-1.0);

Pose bodyPose(const Model& m, int b) { return b == kGround ? Pose{} : m.bodies[b].initial_pose; }

int findJoint(const Model& m, const std::string& name) {
  for (size_t i = 0; i < m.joints.size(); ++i)
    if (m.joints[i].name == name) return static_cast<int>(i);
  return -1;
}

const Link* findLink(const Model& m, const std::string& name) {
  for (const Link& l : m.links)
    if (l.name == name) return &l;
  return nullptr;
}

// At the initial placement a tree joint's anchors coincide and its axes agree in world.
void expectJointAssembled(const Model& m, const Joint& j, double tol) {
  const Pose A = bodyPose(m, j.body_a), B = bodyPose(m, j.body_b);
  EXPECT_LT((A.apply(j.anchor_a) - B.apply(j.anchor_b)).norm(), tol) << j.name;
  EXPECT_LT((A.rotate(j.axis_a) - B.rotate(j.axis_b)).norm(), tol) << j.name;
  EXPECT_NEAR(j.axis_a.norm(), 1.0, kTight) << j.name;
  EXPECT_NEAR(j.axis_b.norm(), 1.0, kTight) << j.name;
}

// Rotation angle of q about unit axis n (q assumed to be about n).
double angleAbout(const Quat& q, const Vec3& n) { return 2.0 * std::atan2(q.vec().dot(n), q.w()); }

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string errorOf(const std::string& path) {
  try {
    loadScene(path);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<no error>";
}

std::string errorOfString(const std::string& xml, const std::string& name = "mem.urdf") {
  try {
    loadSceneFromString(xml, name);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "<no error>";
}

// A ground link "world" and one free body "b" (COM at its link origin).
const char* kHead = R"(<?xml version="1.0"?>
<robot name="t">
  <link name="world"/>
  <link name="b"><inertial><mass value="2"/>
    <inertia ixx="1e-2" ixy="0" ixz="0" iyy="2e-2" iyz="0" izz="3e-2"/></inertial></link>
)";

}  // namespace

// ------------------------------------------------------------------ demo scenes

TEST(SceneLoader, Ball) {
  const Model m = loadScene(scenePath("urdf/ball.urdf"));
  EXPECT_EQ(m.world_frame, "world");
  ASSERT_EQ(m.bodies.size(), 1u);
  EXPECT_EQ(m.bodies[0].name, "ball");
  EXPECT_DOUBLE_EQ(m.bodies[0].mass, 1.0);
  EXPECT_LT((m.bodies[0].inertia - 1e-3 * Mat3::Identity()).norm(), kTight);  // 2/5 m r^2
  EXPECT_LT((m.bodies[0].initial_pose.p - Vec3(0, 0, 1.05)).norm(), kTight);
  EXPECT_NEAR(m.bodies[0].initial_pose.q.angularDistance(Quat::Identity()), 0.0, kTight);
  EXPECT_TRUE(m.bodies[0].initial_velocity.isZero());
  EXPECT_TRUE(m.joints.empty());  // floating joint: placement only
  EXPECT_EQ(m.links.size(), 2u);
  ASSERT_EQ(m.contacts.size(), 1u);
  const ContactPair& c = m.contacts[0];
  EXPECT_EQ(c.name, "ground");
  EXPECT_EQ(c.a.type, ShapeType::Sphere);
  EXPECT_EQ(c.a.body, 0);
  EXPECT_DOUBLE_EQ(c.a.radius, 0.05);
  EXPECT_EQ(c.b.type, ShapeType::Plane);
  EXPECT_EQ(c.b.body, kGround);
  EXPECT_LT(c.b.pose.p.norm(), kTight);
  EXPECT_DOUBLE_EQ(c.mu, 0.0);
  EXPECT_DOUBLE_EQ(c.e, 0.9);
  // Bottom of the ball exactly 1 m above the plane.
  EXPECT_NEAR(m.bodies[0].initial_pose.p.z() - c.a.radius, 1.0, kTight);
  EXPECT_DOUBLE_EQ(m.settings.dt, 1e-4);
  EXPECT_LT((m.settings.gravity - Vec3(0, 0, -9.81)).norm(), kTight);
  EXPECT_EQ(m.source_file, scenePath("urdf/ball.urdf"));
}

TEST(SceneLoader, SlopeBlockRestsFlatOnPlane) {
  const Model m = loadScene(scenePath("urdf/slope.urdf"));
  ASSERT_EQ(m.bodies.size(), 1u);
  ASSERT_EQ(m.contacts.size(), 1u);
  const ContactPair& c = m.contacts[0];
  EXPECT_EQ(c.name, "slide");
  EXPECT_DOUBLE_EQ(c.mu, 0.3);
  const Shape& box = c.a.type == ShapeType::Box ? c.a : c.b;
  const Shape& plane = c.a.type == ShapeType::Box ? c.b : c.a;
  ASSERT_EQ(box.type, ShapeType::Box);
  ASSERT_EQ(plane.type, ShapeType::Plane);
  EXPECT_LT((box.half_extents - Vec3(0.05, 0.05, 0.05)).norm(), kTight);
  const double a = 15.0 * kPi / 180.0;
  const Quat tilt(Eigen::AngleAxisd(a, Vec3::UnitX()));
  EXPECT_NEAR(plane.pose.q.angularDistance(tilt), 0.0, 1e-12);
  const Pose block = m.bodies[0].initial_pose * box.pose;
  EXPECT_LT((block.p - Vec3(0, -0.05 * std::sin(a), 0.05 * std::cos(a))).norm(), 1e-12);
  // Faces parallel, gap 0: every bottom corner lies in the plane.
  const Vec3 n = plane.pose.rotate(Vec3::UnitZ());
  EXPECT_LT((block.rotate(Vec3::UnitZ()) - n).norm(), 1e-12);
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      EXPECT_NEAR(n.dot(block.apply(Vec3(0.05 * sx, 0.05 * sy, -0.05)) - plane.pose.p), 0.0, 1e-12);
}

TEST(SceneLoader, PendulumPlacedAtInitialAngle) {
  const Model m = loadScene(scenePath("urdf/pendulum.urdf"));
  ASSERT_EQ(m.bodies.size(), 1u);
  ASSERT_EQ(m.joints.size(), 1u);
  const Joint& j = m.joints[0];
  EXPECT_EQ(j.name, "hinge");
  EXPECT_EQ(j.type, JointType::Revolute);
  EXPECT_EQ(j.body_a, kGround);
  EXPECT_EQ(j.body_b, 0);
  EXPECT_FALSE(j.loop);
  EXPECT_EQ(j.clearance, -1);
  EXPECT_LT(j.anchor_a.norm(), kTight);
  EXPECT_LT((j.anchor_b - Vec3(0, 0, 1)).norm(), kTight);  // hinge 1 m above the COM
  EXPECT_LT((j.axis_a - Vec3::UnitY()).norm(), kTight);
  EXPECT_LT((j.axis_b - Vec3::UnitY()).norm(), kTight);
  EXPECT_NEAR(j.rel_rot_zero.angularDistance(Quat::Identity()), 0.0, kTight);
  // +30 deg about +y turns (0, 0, -1) into (-sin 30, 0, -cos 30).
  const Pose& p = m.bodies[0].initial_pose;
  EXPECT_LT((p.p - Vec3(-0.5, 0, -std::sqrt(3.0) / 2)).norm(), kTight);
  EXPECT_NEAR(p.q.angularDistance(Quat(Eigen::AngleAxisd(kPi / 6, Vec3::UnitY()))), 0.0, kTight);
  EXPECT_NEAR(angleAbout(j.rel_rot_zero.conjugate() * p.q, j.axis_b), kPi / 6, kTight);
  expectJointAssembled(m, j, kTight);
  EXPECT_DOUBLE_EQ(m.bodies[0].mass, 1.0);
  EXPECT_LT((m.bodies[0].inertia - 1e-3 * Mat3::Identity()).norm(), kTight);
}

TEST(SceneLoader, FourBarClosesAndLoopJointIsMarked) {
  const Model m = loadScene(scenePath("urdf/fourbar.urdf"));
  ASSERT_EQ(m.bodies.size(), 3u);
  const int crank = m.findBody("crank"), coupler = m.findBody("coupler"), rocker = m.findBody("rocker");
  ASSERT_GE(crank, 0);
  ASSERT_GE(coupler, 0);
  ASSERT_GE(rocker, 0);
  EXPECT_DOUBLE_EQ(m.bodies[crank].mass, 0.1);
  EXPECT_DOUBLE_EQ(m.bodies[coupler].mass, 0.4);
  EXPECT_DOUBLE_EQ(m.bodies[rocker].mass, 0.3);
  EXPECT_NEAR(m.bodies[coupler].inertia(2, 2), 0.4 * 0.16 / 12, kTight);  // m L^2 / 12
  ASSERT_EQ(m.joints.size(), 4u);
  for (const Joint& j : m.joints) {
    EXPECT_EQ(j.type, JointType::Revolute);
    expectJointAssembled(m, j, 1e-9);  // placed closed, loop included
  }
  const int loop = findJoint(m, "loop");
  ASSERT_GE(loop, 0);
  EXPECT_TRUE(m.joints[loop].loop);
  EXPECT_EQ(m.joints[loop].body_a, kGround);
  EXPECT_EQ(m.joints[loop].body_b, rocker);
  EXPECT_LT((m.joints[loop].anchor_a - Vec3(0.4, 0, 0)).norm(), kTight);
  for (const char* n : {"crank_joint", "coupler_joint", "rocker_joint"})
    EXPECT_FALSE(m.joints[findJoint(m, n)].loop) << n;
  // Geometry: crank straight up, COMs at bar midpoints, bar lengths.
  EXPECT_LT((m.bodies[crank].initial_pose.p - Vec3(0, 0, 0.05)).norm(), kTight);
  const Vec3 B(0, 0, 0.1), O4(0.4, 0, 0);
  const Vec3 C = 2.0 * m.bodies[rocker].initial_pose.p - O4;
  EXPECT_NEAR((C - B).norm(), 0.4, 1e-9);
  EXPECT_NEAR((C - O4).norm(), 0.3, 1e-9);
  EXPECT_LT((m.bodies[coupler].initial_pose.p - 0.5 * (B + C)).norm(), 1e-9);
  EXPECT_GT(C.z(), 0.0);  // upper assembly branch
  // The massless pivot link rides on the rocker, 0.15 m from its COM.
  const Link* pivot = findLink(m, "rocker_pivot");
  ASSERT_NE(pivot, nullptr);
  EXPECT_EQ(pivot->body, rocker);
  EXPECT_LT((pivot->in_body.p - Vec3(0.15, 0, 0)).norm(), kTight);
  EXPECT_EQ(m.links.size(), 5u);
  // Initial crank velocity: w = 5 rad/s about y, COM velocity w x r = (0.25, 0, 0).
  EXPECT_LT((m.bodies[crank].initial_angular_velocity - Vec3(0, 5, 0)).norm(), kTight);
  EXPECT_LT((m.bodies[crank].initial_velocity - Vec3(0.25, 0, 0)).norm(), kTight);
  EXPECT_TRUE(m.bodies[rocker].initial_angular_velocity.isZero());
}

TEST(SceneLoader, SpringMass) {
  const Model m = loadScene(scenePath("urdf/spring_mass.urdf"));
  ASSERT_EQ(m.bodies.size(), 1u);
  EXPECT_LT((m.bodies[0].initial_pose.p - Vec3(0.5, 0, 0)).norm(), kTight);
  ASSERT_EQ(m.joints.size(), 1u);
  const Joint& j = m.joints[0];
  EXPECT_EQ(j.type, JointType::Prismatic);
  // Prismatic joint at position 0.5: the child anchor is 0.5 m along the axis.
  EXPECT_LT((bodyPose(m, j.body_b).apply(j.anchor_b) - bodyPose(m, j.body_a).apply(j.anchor_a) -
             0.5 * bodyPose(m, j.body_a).rotate(j.axis_a)).norm(), kTight);
  ASSERT_EQ(m.springs.size(), 1u);
  const Spring& s = m.springs[0];
  EXPECT_EQ(s.name, "spring");
  EXPECT_EQ(s.type, SpringType::Linear);
  EXPECT_DOUBLE_EQ(s.stiffness, 100.0);
  EXPECT_DOUBLE_EQ(s.rest, 0.4);
  EXPECT_DOUBLE_EQ(s.damping, 0.0);
  EXPECT_EQ(s.body_a, kGround);
  EXPECT_EQ(s.body_b, 0);
  EXPECT_LT(s.end_a.norm(), kTight);
  EXPECT_LT(s.end_b.norm(), kTight);
  EXPECT_TRUE(m.settings.gravity.isZero());
}

TEST(SceneLoader, SpringRestLengthDefaultsToInitialDistance) {
  std::string xml = slurp(scenePath("urdf/spring_mass.urdf"));
  const std::string attr = " rest_length=\"0.4\"";
  const size_t at = xml.find(attr);
  ASSERT_NE(at, std::string::npos);
  xml.erase(at, attr.size());
  Model m = loadSceneFromString(xml, "spring_mass_no_rest");
  ASSERT_EQ(m.springs.size(), 1u);
  EXPECT_NEAR(m.springs[0].rest, 0.5, kTight);  // no preload
  // Off-axis ends: rest = |(0.5 + 0.1, 0, 0.2) - (0, 0.3, 0)|.
  const size_t e1 = xml.find("<end link=\"world\" xyz=\"0 0 0\"/>");
  ASSERT_NE(e1, std::string::npos);
  xml.replace(e1, std::string("<end link=\"world\" xyz=\"0 0 0\"/>").size(), "<end link=\"world\" xyz=\"0 0.3 0\"/>");
  const size_t e2 = xml.find("<end link=\"mass\" xyz=\"0 0 0\"/>");
  ASSERT_NE(e2, std::string::npos);
  xml.replace(e2, std::string("<end link=\"mass\" xyz=\"0 0 0\"/>").size(), "<end link=\"mass\" xyz=\"0.1 0 0.2\"/>");
  m = loadSceneFromString(xml, "spring_mass_no_rest_2");
  EXPECT_NEAR(m.springs[0].rest, std::sqrt(0.36 + 0.09 + 0.04), kTight);
  EXPECT_LT((m.springs[0].end_b - Vec3(0.1, 0, 0.2)).norm(), kTight);
}

TEST(SceneLoader, JournalClearanceFields) {
  const Model m = loadScene(scenePath("urdf/journal.urdf"));
  ASSERT_EQ(m.bodies.size(), 1u);
  ASSERT_EQ(m.joints.size(), 1u);  // the fixed pin mount attaches a ground link: no joint
  ASSERT_EQ(m.clearance_joints.size(), 1u);
  const Joint& j = m.joints[0];
  const ClearanceJoint& c = m.clearance_joints[0];
  EXPECT_EQ(j.name, "pin_joint");
  EXPECT_EQ(j.clearance, 0);
  EXPECT_EQ(c.name, "pin_joint");
  EXPECT_EQ(c.joint, 0);
  EXPECT_EQ(c.journal_body, kGround);  // journal="parent": the pin
  EXPECT_EQ(c.bearing_body, 0);
  EXPECT_LT((c.journal_center - Vec3(0, 0, 0.1)).norm(), kTight);  // world frame
  EXPECT_LT(c.bearing_center.norm(), kTight);
  EXPECT_LT((c.journal_axis - Vec3::UnitX()).norm(), kTight);
  EXPECT_LT((c.bearing_axis - Vec3::UnitX()).norm(), kTight);
  EXPECT_NEAR(c.bearing_ref.norm(), 1.0, kTight);
  EXPECT_NEAR(c.bearing_ref.dot(c.bearing_axis), 0.0, kTight);
  EXPECT_DOUBLE_EQ(c.radius, 5e-3);
  EXPECT_DOUBLE_EQ(c.radial, 0.05e-3);
  EXPECT_DOUBLE_EQ(c.length, 20e-3);
  EXPECT_DOUBLE_EQ(c.axial, 0.2e-3);
  EXPECT_EQ(c.bumps, 3);
  EXPECT_DOUBLE_EQ(c.bump_radius, 5e-3 / 8);
  EXPECT_DOUBLE_EQ(c.bump_at, 1.5 * (5e-3 + 0.05e-3));
  EXPECT_DOUBLE_EQ(c.mu, 0.2);
  EXPECT_DOUBLE_EQ(c.e, 0.0);
  EXPECT_EQ(c.src.line, 47);  // the <clearance> element in journal.urdf
  const Link* pin = findLink(m, "pin");
  ASSERT_NE(pin, nullptr);
  EXPECT_EQ(pin->body, kGround);
  EXPECT_LT((pin->in_body.p - Vec3(0, 0, 0.1)).norm(), kTight);
  EXPECT_DOUBLE_EQ(m.bodies[0].mass, 0.2);
  expectJointAssembled(m, j, kTight);
}

TEST(SceneLoader, ClearancePendulum) {
  const Model m = loadScene(scenePath("urdf/clearance_pendulum.urdf"));
  ASSERT_EQ(m.bodies.size(), 1u);
  ASSERT_EQ(m.clearance_joints.size(), 1u);
  const ClearanceJoint& c = m.clearance_joints[0];
  EXPECT_EQ(c.journal_body, kGround);
  EXPECT_EQ(c.bearing_body, 0);
  EXPECT_LT(c.journal_center.norm(), kTight);
  EXPECT_LT((c.bearing_center - Vec3(0, 0, 0.1)).norm(), kTight);  // hinge 0.1 m above the COM
  EXPECT_LT((c.bearing_axis - Vec3::UnitY()).norm(), kTight);
  EXPECT_DOUBLE_EQ(c.radius, 2e-3);
  EXPECT_DOUBLE_EQ(c.radial, 50e-6);
  EXPECT_DOUBLE_EQ(c.length, 5e-3);
  EXPECT_DOUBLE_EQ(c.axial, 0.1e-3);
  EXPECT_DOUBLE_EQ(c.mu, 0.1);
  EXPECT_DOUBLE_EQ(m.settings.dt, 1e-5);
  EXPECT_LT((m.bodies[0].initial_pose.p - Vec3(-0.05, 0, -0.1 * std::sqrt(3.0) / 2)).norm(), kTight);
  EXPECT_EQ(m.joints[0].clearance, 0);
}

TEST(SceneLoader, EveryDemoSceneLoads) {
  for (const char* f : {"ball", "slope", "pendulum", "fourbar", "spring_mass", "journal",
                        "clearance_pendulum"}) {
    EXPECT_NO_THROW(loadScene(scenePath(std::string("urdf/") + f + ".urdf"))) << f;
  }
}

// ------------------------------------------------------------------ frames and conversions

// The contact shapes of CAD edge-face contacts: ring (full and arc), face, and a
// cylinder limited to an arc; the defaults of start and span.
TEST(SceneLoader, RingFaceAndCylinderArcShapes) {
  const std::string xml = std::string(kHead) + R"(
  <joint name="bj" type="floating"><parent link="world"/><child link="b"/></joint>
  <nscd>
    <contact name="full"><shape link="b" type="ring" radius="0.5e-3"/>
      <shape link="world" type="face" size="6.2e-3 4e-3"><origin xyz="0 0 -1e-3"/></shape></contact>
    <contact name="half"><shape link="world" type="plane"/>
      <shape link="b" type="ring" radius="0.48e-3" start="-1.5707963" span="3.14159265"/></contact>
    <contact name="arc"><shape link="b" type="ring" radius="0.48e-3" span="6.283185307179586"/>
      <shape link="world" type="cylinder" radius="5.63e-3" length="4e-3" start="0.2" span="1.1"/></contact>
    <contact name="guide"><shape link="world" type="cylinder" radius="5.9e-3" length="3e-3" hollow="true"/>
      <shape link="b" type="ring" radius="0.5e-3"/></contact>
  </nscd>
</robot>)";
  const Model m = loadSceneFromString(xml, "rings");
  ASSERT_EQ(m.contacts.size(), 4u);
  const ContactPair& full = m.contacts[0];
  EXPECT_EQ(full.a.type, ShapeType::Ring);
  EXPECT_DOUBLE_EQ(full.a.radius, 0.5e-3);
  EXPECT_DOUBLE_EQ(full.a.start, 0.0);
  EXPECT_DOUBLE_EQ(full.a.span, 2 * kPi);
  EXPECT_EQ(full.b.type, ShapeType::Face);
  EXPECT_LT((full.b.half_extents - Vec3(3.1e-3, 2e-3, 0)).norm(), kTight);
  EXPECT_LT((full.b.pose.p - Vec3(0, 0, -1e-3)).norm(), kTight);
  const ContactPair& half = m.contacts[1];
  EXPECT_EQ(half.b.type, ShapeType::Ring);
  EXPECT_DOUBLE_EQ(half.b.start, -1.5707963);
  EXPECT_DOUBLE_EQ(half.b.span, 3.14159265);
  const ContactPair& arc = m.contacts[2];
  EXPECT_DOUBLE_EQ(arc.a.span, 2 * kPi);
  EXPECT_EQ(arc.b.type, ShapeType::Cylinder);
  EXPECT_DOUBLE_EQ(arc.b.start, 0.2);
  EXPECT_DOUBLE_EQ(arc.b.span, 1.1);
  EXPECT_DOUBLE_EQ(arc.b.length, 4e-3);
  EXPECT_FALSE(arc.b.hollow);
  EXPECT_TRUE(m.contacts[3].a.hollow);
}

// rpy in <nscd> origins follows the URDF convention: compare with urdfdom's reading of
// the same rpy in a fixed joint.
TEST(SceneLoader, NscdOriginRpyMatchesUrdfConvention) {
  const std::string xml = std::string(kHead) + R"(
  <link name="tag"/>
  <joint name="tag_mount" type="fixed"><parent link="world"/><child link="tag"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.3 -0.7 1.1"/></joint>
  <joint name="bj" type="floating"><parent link="world"/><child link="b"/></joint>
  <nscd><contact name="c"><shape link="b" type="sphere" radius="0.1"/>
    <shape link="world" type="plane"><origin xyz="0.1 0.2 0.3" rpy="0.3 -0.7 1.1"/></shape></contact></nscd>
</robot>)";
  const Model m = loadSceneFromString(xml, "rpy");
  const Link* tag = findLink(m, "tag");
  ASSERT_NE(tag, nullptr);
  EXPECT_EQ(tag->body, kGround);
  EXPECT_NEAR(m.contacts[0].b.pose.q.angularDistance(tag->in_body.q), 0.0, 1e-12);
  EXPECT_LT((m.contacts[0].b.pose.p - tag->in_body.p).norm(), kTight);
  // And the convention itself: R = Rz(yaw) Ry(pitch) Rx(roll).
  const Quat want = Eigen::AngleAxisd(1.1, Vec3::UnitZ()) * Eigen::AngleAxisd(-0.7, Vec3::UnitY()) *
                    Eigen::AngleAxisd(0.3, Vec3::UnitX());
  EXPECT_NEAR(tag->in_body.q.angularDistance(want), 0.0, 1e-12);
}

// Body frame = rotated, offset inertial origin; everything attached to the link must be
// converted into it.
TEST(SceneLoader, AttachmentsAreConvertedToTheBodyFrame) {
  const std::string xml = R"(<?xml version="1.0"?>
<robot name="t">
  <link name="world"/>
  <link name="arm"><inertial><origin xyz="0.2 0 0" rpy="0 0 1.5707963267948966"/><mass value="1"/>
    <inertia ixx="1e-2" ixy="0" ixz="0" iyy="2e-2" iyz="0" izz="3e-2"/></inertial></link>
  <link name="tip"/>
  <joint name="tip_mount" type="fixed"><parent link="arm"/><child link="tip"/>
    <origin xyz="0.5 0 0"/></joint>
  <joint name="hinge" type="revolute"><parent link="world"/><child link="arm"/>
    <origin xyz="0 0 1" rpy="0 0 1.5707963267948966"/><axis xyz="0 0 2"/>
    <limit lower="-3" upper="3" effort="0" velocity="0"/></joint>
  <nscd>
    <initial joint="hinge" position="0.25"/>
    <actuator name="push" type="force" link="tip" xyz="0 0.1 0" direction="0 0 3"/>
    <actuator name="slide" type="prescribed" link="arm" axis="2 0 0"/>
    <actuator name="servo" type="position" joint="hinge" kp="2" kd="0.1" max_effort="5"/>
    <actuator name="servo2" type="position" joint="hinge" command="-1"/>
    <actuator name="drive" type="prescribed" joint="hinge"/>
    <actuator name="twist" type="torque" link="tip" axis="2 0 0" schedule="0:-0.5,1e-3:-0.5,1e-3:0"/>
    <spring name="tors" type="torsion" joint="hinge" stiffness="0.5"/>
    <contact name="c"><shape link="tip" type="sphere" radius="0.01"><origin xyz="0 0 0.02"/></shape>
      <shape link="world" type="plane"/></contact>
  </nscd>
</robot>)";
  const Model m = loadSceneFromString(xml, "conv");
  ASSERT_EQ(m.bodies.size(), 1u);
  // Link frame in body frame: inverse of the inertial origin (rotation 90 deg about z).
  const Quat rz(Eigen::AngleAxisd(kPi / 2, Vec3::UnitZ()));
  auto linkToBody = [&](const Vec3& x) { return rz.conjugate() * (x - Vec3(0.2, 0, 0)); };
  // Force at tip (0.5, 0.1, 0) of the arm link -> body frame; direction rotated and normalised.
  const Actuator& push = m.actuators[m.findActuator("push")];
  EXPECT_EQ(push.type, ActuatorType::Force);
  EXPECT_EQ(push.body, 0);
  EXPECT_LT((push.point - linkToBody(Vec3(0.5, 0.1, 0))).norm(), kTight);
  EXPECT_LT((push.point - Vec3(0.1, -0.3, 0)).norm(), kTight);
  EXPECT_LT((push.direction - Vec3(0, 0, 1)).norm(), kTight);
  EXPECT_DOUBLE_EQ(push.initial_command, 0.0);
  // Prescribed axis: link x at the initial pose, in world. The link is turned by
  // 90 deg (joint origin) + 0.25 rad (initial position) about z.
  const Actuator& slide = m.actuators[m.findActuator("slide")];
  EXPECT_EQ(slide.type, ActuatorType::Prescribed);
  EXPECT_EQ(slide.body, 0);
  const double th = kPi / 2 + 0.25;
  EXPECT_LT((slide.axis - Vec3(std::cos(th), std::sin(th), 0)).norm(), kTight);
  EXPECT_DOUBLE_EQ(slide.initial_command, 0.0);
  EXPECT_FALSE(slide.axis_only);  // constrain="all", the default
  // Position actuator starts at the initial joint position; command= overrides it.
  const Actuator& servo = m.actuators[m.findActuator("servo")];
  EXPECT_EQ(servo.joint, findJoint(m, "hinge"));
  EXPECT_DOUBLE_EQ(servo.initial_command, 0.25);
  EXPECT_DOUBLE_EQ(servo.kp, 2.0);
  EXPECT_DOUBLE_EQ(servo.kd, 0.1);
  EXPECT_DOUBLE_EQ(servo.max_effort, 5.0);
  EXPECT_DOUBLE_EQ(m.actuators[m.findActuator("servo2")].initial_command, -1.0);
  EXPECT_DOUBLE_EQ(m.actuators[m.findActuator("drive")].initial_command, 0.25);
  EXPECT_EQ(m.actuators[m.findActuator("drive")].joint, findJoint(m, "hinge"));
  EXPECT_TRUE(m.actuators[m.findActuator("drive")].schedule.empty());
  // Torque: its axis (link x) in the body frame, normalised; the schedule as written.
  const Actuator& twist = m.actuators[m.findActuator("twist")];
  EXPECT_EQ(twist.type, ActuatorType::Torque);
  EXPECT_EQ(twist.body, 0);
  EXPECT_LT((twist.direction - rz.conjugate() * Vec3::UnitX()).norm(), kTight);
  EXPECT_DOUBLE_EQ(twist.initial_command, 0.0);
  ASSERT_EQ(twist.schedule.size(), 3u);
  EXPECT_EQ(twist.schedule[0], std::make_pair(0.0, -0.5));
  EXPECT_EQ(twist.schedule[1], std::make_pair(1e-3, -0.5));
  EXPECT_EQ(twist.schedule[2], std::make_pair(1e-3, 0.0));
  // Torsion spring: between the joint's bodies, rest angle from the URDF zero.
  ASSERT_EQ(m.springs.size(), 1u);
  EXPECT_EQ(m.springs[0].type, SpringType::Torsion);
  EXPECT_EQ(m.springs[0].body_a, kGround);
  EXPECT_EQ(m.springs[0].body_b, 0);
  EXPECT_EQ(m.springs[0].joint, findJoint(m, "hinge"));
  EXPECT_DOUBLE_EQ(m.springs[0].rest, 0.0);
  // Shape on the massless tip link: tip origin (0.5,0,0) + (0,0,0.02) in the arm link.
  EXPECT_EQ(m.contacts[0].a.body, 0);
  EXPECT_LT((m.contacts[0].a.pose.p - linkToBody(Vec3(0.5, 0, 0.02))).norm(), kTight);
  // Joint: axis normalised, anchors in body frames, rel_rot_zero = q_a^-1 q_b at zero.
  const Joint& j = m.joints[findJoint(m, "hinge")];
  EXPECT_LT((j.axis_a - Vec3::UnitZ()).norm(), kTight);
  EXPECT_LT((j.axis_b - Vec3::UnitZ()).norm(), kTight);
  EXPECT_LT((j.anchor_a - Vec3(0, 0, 1)).norm(), kTight);
  EXPECT_LT((j.anchor_b - linkToBody(Vec3::Zero())).norm(), kTight);
  // Body in world = Rz(90 deg + 0.25) * inertial origin rotation (90 deg); at zero: 180 deg.
  EXPECT_NEAR(j.rel_rot_zero.angularDistance(Quat(Eigen::AngleAxisd(kPi, Vec3::UnitZ()))), 0.0, 1e-12);
  expectJointAssembled(m, j, kTight);
  const Quat qb = m.bodies[0].initial_pose.q;
  EXPECT_NEAR(angleAbout(j.rel_rot_zero.conjugate() * qb, j.axis_b), 0.25, kTight);
  EXPECT_LT((m.bodies[0].initial_pose.p - (Vec3(0, 0, 1) + Vec3(std::cos(th), std::sin(th), 0) * 0.2)).norm(), kTight);
  // tf links: arm and tip ride on the body, world is ground.
  EXPECT_EQ(findLink(m, "tip")->body, 0);
  EXPECT_EQ(findLink(m, "world")->body, kGround);
}

TEST(SceneLoader, FixedJointBetweenBodiesAndInitialVelocity) {
  const std::string xml = std::string(kHead) + R"(
  <link name="c"><inertial><origin xyz="0 0 0.1"/><mass value="1"/>
    <inertia ixx="1e-2" ixy="0" ixz="0" iyy="1e-2" iyz="0" izz="1e-2"/></inertial></link>
  <link name="ground2"/>
  <joint name="g2" type="fixed"><parent link="world"/><child link="ground2"/><origin xyz="1 0 0"/></joint>
  <joint name="bj" type="floating"><parent link="ground2"/><child link="b"/><origin xyz="0 0 2"/></joint>
  <joint name="weld" type="fixed"><parent link="b"/><child link="c"/><origin xyz="0 0.5 0"/></joint>
  <nscd><initial link="c" vx="1" vy="2" wz="3"/></nscd>
</robot>)";
  const Model m = loadSceneFromString(xml, "fixed");
  ASSERT_EQ(m.bodies.size(), 2u);
  ASSERT_EQ(m.joints.size(), 1u);  // g2 (ground link) and bj (floating) make no joint
  const Joint& w = m.joints[0];
  EXPECT_EQ(w.type, JointType::Fixed);
  EXPECT_EQ(w.body_a, m.findBody("b"));
  EXPECT_EQ(w.body_b, m.findBody("c"));
  EXPECT_LT((w.anchor_a - Vec3(0, 0.5, 0)).norm(), kTight);
  EXPECT_LT((w.anchor_b - Vec3(0, 0, -0.1)).norm(), kTight);
  expectJointAssembled(m, w, kTight);
  EXPECT_LT((m.bodies[m.findBody("b")].initial_pose.p - Vec3(1, 0, 2)).norm(), kTight);
  EXPECT_LT((m.bodies[m.findBody("c")].initial_pose.p - Vec3(1, 0.5, 2.1)).norm(), kTight);
  // <initial link> is the world velocity of that link's body COM, and its spin.
  EXPECT_LT((m.bodies[m.findBody("c")].initial_velocity - Vec3(1, 2, 0)).norm(), kTight);
  EXPECT_LT((m.bodies[m.findBody("c")].initial_angular_velocity - Vec3(0, 0, 3)).norm(), kTight);
  EXPECT_TRUE(m.bodies[m.findBody("b")].initial_velocity.isZero());
}

TEST(SceneLoader, ClearanceOnLoopJointWithChildJournal) {
  const std::string xml = std::string(kHead) + R"(
  <joint name="bj" type="floating"><parent link="world"/><child link="b"/><origin xyz="0 0 1"/></joint>
  <nscd>
    <joint name="pivot" type="continuous" parent="world" child="b">
      <origin xyz="0 0 1"/><axis xyz="0 1 0"/></joint>
    <clearance joint="pivot" journal="child" radius="1e-3" radial="1e-5" length="2e-3" axial="1e-4"
               bumps="4" bump_radius="1e-4" bump_at="2e-3" mu="0.3" e="0.5"/>
  </nscd>
</robot>)";
  const Model m = loadSceneFromString(xml, "loopclear");
  ASSERT_EQ(m.joints.size(), 1u);
  EXPECT_TRUE(m.joints[0].loop);
  ASSERT_EQ(m.clearance_joints.size(), 1u);
  const ClearanceJoint& c = m.clearance_joints[0];
  EXPECT_EQ(c.journal_body, 0);
  EXPECT_EQ(c.bearing_body, kGround);
  EXPECT_LT((c.bearing_center - Vec3(0, 0, 1)).norm(), kTight);
  EXPECT_LT(c.journal_center.norm(), kTight);
  EXPECT_EQ(c.bumps, 4);
  EXPECT_DOUBLE_EQ(c.bump_radius, 1e-4);
  EXPECT_DOUBLE_EQ(c.bump_at, 2e-3);
  EXPECT_DOUBLE_EQ(c.e, 0.5);
  EXPECT_EQ(m.joints[0].clearance, 0);
}

// ------------------------------------------------------------------ bad scenes

struct BadCase {
  const char* file;
  int line;            // 0: no line in the message
  const char* needle;  // part of the message
};

const BadCase kBad[] = {
    {"01_truncated_xml.urdf", 5, "XML error"},
    {"02_empty.urdf", 0, "empty file"},
    {"03_not_urdf.urdf", 3, "not a URDF"},
    {"04_unknown_link_in_contact.urdf", 20, "unknown link 'bal'"},
    {"05_nonpositive_mass.urdf", 7, "mass must be > 0"},
    {"06_huge_mass.urdf", 7, "exceeds the limit"},
    {"07_inertia_not_positive_definite.urdf", 8, "not positive definite"},
    {"08_clearance_on_prismatic.urdf", 20, "clearance on prismatic joint 'slider'"},
    {"09_negative_radial_clearance.urdf", 18, "'radial' of <clearance> must be > 0"},
    {"10_nan_attribute.urdf", 18, "attribute 'radius' of <shape>: 'nan' is not a number"},
    {"11_unknown_shape_type.urdf", 18, "unknown shape type 'cone'"},
    {"12_joint_referenced_twice.urdf", 20, "second <clearance>"},
    {"13_dt_zero.urdf", 15, "setting 'dt' must be in (0, 0.1]"},
    {"14_negative_tolerance.urdf", 16, "setting 'tolerance'"},
    {"15_unknown_nscd_element.urdf", 17, "unknown element <damper> in <nscd>"},
    {"16_unknown_actuator_type.urdf", 18, "unknown actuator type 'velocity'"},
    {"17_duplicate_contact_name.urdf", 21, "duplicate contact name 'ground'"},
    {"18_unsupported_shape_pair.urdf", 26, "cylinder-cylinder pairs are not supported"},
    {"19_massless_link_on_revolute.urdf", 6, "has no <inertial>"},
    {"20_initial_unknown_joint.urdf", 19, "unknown joint 'hinj'"},
    {"21_ring_span_too_large.urdf", 18, "attribute 'span' of <shape> must be in (0, 6.28"},
    {"22_face_size_one_number.urdf", 19, "attribute 'size' of <shape> type 'face': expected 2 numbers, got '0.2'"},
    {"23_actuator_schedule_decreasing.urdf", 17, "attribute 'schedule' of <actuator>: schedule 'seat=0:-0.015,0.002:-0.015,0.001:0': times must not decrease"},
    {"24_spring_load_on_third_body.urdf", 47, "<force> of spring 'pull': link 'lever' is on body 'lever', not on one of the spring's bodies (ground, body 'plate')"},
    {"25_torsion_joint_and_angle.urdf", 45, "torsion spring 'twist' needs either a joint attribute or one <angle> child, got the joint and 1 <angle>"},
    {"26_torsion_without_angle.urdf", 45, "torsion spring 'twist' needs either a joint attribute or one <angle> child, got 0 <angle>"},
    {"27_spring_force_zero_direction.urdf", 46, "<force> of spring 'twist': direction must be non-zero"},
    {"28_angle_links_on_one_body.urdf", 46, "<angle> of spring 'twist': links 'arm' and 'arm_tip' are both on body 'arm'"},
    {"29_couple_without_scale.urdf", 47, "<couple> is missing attribute 'scale'"},
    {"30_spring_load_on_ground.urdf", 46, "<couple> of spring 'twist': link 'world' is ground, which takes no load"},
    {"31_angle_in_linear_spring.urdf", 47, "unknown element <angle> in <spring>"},
    {"32_line_break_in_attribute.urdf", 19, "unknown shape type 'co\\nne'"},
};

TEST(SceneLoaderBad, EachBadSceneIsRefusedWithFileLineAndReason) {
  for (const BadCase& b : kBad) {
    const std::string path = scenePath(std::string("test/scenes/bad/") + b.file);
    const std::string msg = errorOf(path);
    const std::string prefix = b.line > 0 ? path + ":" + std::to_string(b.line) + ": " : path + ": ";
    EXPECT_EQ(msg.rfind(prefix, 0), 0u) << b.file << ": " << msg;
    EXPECT_NE(msg.find(b.needle), std::string::npos) << b.file << ": " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << b.file << ": " << msg;
    // The file's own comment states the same line.
    const std::string text = slurp(path);
    const size_t at = text.find("expect: line ");
    if (b.line > 0) {
      ASSERT_NE(at, std::string::npos) << b.file;
      EXPECT_EQ(std::atoi(text.c_str() + at + 13), b.line) << b.file;
    }
  }
}

TEST(SceneLoaderBad, TableCoversEveryBadScene) {
  const std::string dir = scenePath("test/scenes/bad");
  DIR* d = opendir(dir.c_str());
  ASSERT_NE(d, nullptr);
  int n = 0;
  for (dirent* e; (e = readdir(d));) {
    const std::string f = e->d_name;
    if (f.size() < 5 || f.substr(f.size() - 5) != ".urdf") continue;
    ++n;
    bool listed = false;
    for (const BadCase& b : kBad) listed = listed || f == b.file;
    EXPECT_TRUE(listed) << f << " is not in kBad";
  }
  closedir(d);
  EXPECT_EQ(n, static_cast<int>(sizeof(kBad) / sizeof(kBad[0])));
}

TEST(SceneLoaderBad, MissingFile) {
  const std::string path = scenePath("urdf/no_such_scene.urdf");
  EXPECT_EQ(errorOf(path), path + ": cannot read file");
  EXPECT_EQ(errorOf(scenePath("urdf")).rfind(scenePath("urdf") + ": cannot read file", 0), 0u);  // a directory
}

TEST(SceneLoaderBad, MoreRefusals) {
  const std::string tail = "\n</robot>";
  const std::string fl = R"(<joint name="bj" type="floating"><parent link="world"/><child link="b"/></joint>)";
  const std::string rv = R"(<joint name="j" type="continuous"><parent link="world"/><child link="b"/><axis xyz="0 1 0"/></joint>)";
  const std::string pr = R"(<joint name="j" type="prismatic"><parent link="world"/><child link="b"/><limit lower="0" upper="1" effort="0" velocity="0"/></joint>)";
  const std::string sph = R"(<shape link="b" type="sphere" radius="0.1"/><shape link="world" type="plane"/>)";
  const std::pair<std::string, std::string> cases[] = {
      {"<robot name=\"x\"><link name=\"w\"><inertial><mass value=\"1\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial></link></robot>",
       "root link 'w' must be ground"},
      {std::string(kHead) + R"(<joint name="j" type="planar"><parent link="world"/><child link="b"/></joint>)" + tail, "planar joints are not supported"},
      {std::string(kHead) + R"(<joint name="j" type="continuous"><parent link="world"/><child link="b"/><axis xyz="0 0 0"/></joint>)" + tail, "axis must be non-zero"},
      {std::string(kHead) + R"(<joint name="j" type="revolute"><parent link="world"/><child link="b"/></joint>)" + tail, "URDF error"},
      {std::string(kHead) + fl + fl + tail, "duplicate joint name 'bj'"},
      {std::string(kHead) + fl + R"(<nscd><joint name="bj" type="revolute" parent="world" child="b"/></nscd>)" + tail, "duplicate joint name 'bj'"},
      {std::string(kHead) + fl + R"(<nscd><joint name="l" type="planar" parent="world" child="b"/></nscd>)" + tail, "not supported"},
      {std::string(kHead) + fl + R"(<nscd><joint name="l" type="revolute" parent="b" child="b"/></nscd>)" + tail, "to itself"},
      {std::string(kHead) + fl + R"(<nscd><initial joint="bj" position="1"/></nscd>)" + tail, "only revolute, continuous and prismatic"},
      {std::string(kHead) + fl + R"(<nscd><initial link="nope" vx="1"/></nscd>)" + tail, "unknown link 'nope'"},
      {std::string(kHead) + fl + R"(<nscd><initial link="world" vx="1"/></nscd>)" + tail, "is ground"},
      {std::string(kHead) + fl + R"(<nscd><initial link="b" vq="1"/></nscd>)" + tail, "unknown attribute 'vq' on <initial>"},
      {std::string(kHead) + fl + R"(<nscd><clearance joint="bj" radius="1" radial="1" length="1" axial="1"/></nscd>)" + tail, "imposes nothing"},
      {std::string(kHead) + fl + R"(<nscd><clearance joint="zz" radius="1" radial="1" length="1" axial="1"/></nscd>)" + tail, "unknown joint 'zz'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="0" radial="1" length="1" axial="1"/></nscd>)" + tail, "'radius' of <clearance> must be > 0"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="-1" axial="1"/></nscd>)" + tail, "'length'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="1" axial="0"/></nscd>)" + tail, "'axial'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="1" axial="1" bumps="9"/></nscd>)" + tail, "'bumps'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="1" axial="1" bump_radius="-1"/></nscd>)" + tail, "'bump_radius'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="1" axial="1" mu="-0.1"/></nscd>)" + tail, "'mu'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" radial="1" length="1" axial="1" e="1.1"/></nscd>)" + tail, "'e'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" journal="both" radius="1" radial="1" length="1" axial="1"/></nscd>)" + tail, "'journal'"},
      {std::string(kHead) + rv + R"(<nscd><clearance joint="j" radius="1" length="1" axial="1"/></nscd>)" + tail, "missing attribute 'radial'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="0.1"/></contact></nscd>)" + tail, "exactly two <shape>"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="0.1"/><shape link="b" type="sphere" radius="0.1"/></contact></nscd>)" + tail, "both shapes are on body 'b'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="world" type="sphere" radius="0.1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "both shapes are on ground"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="box" size="1 1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "expected 3 numbers"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="box" size="1 0 1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "size"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="capsule" radius="0.1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "missing attribute 'length'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="abc"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "'abc' is not a number"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="inf"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "not finite"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'radius' of <shape> must be > 0"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "missing attribute 'radius'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0.1" span="0"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'span' of <shape> must be in (0, "},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0.1" span="-1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'span' of <shape> must be in (0, "},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0.1" start="nan"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'start' of <shape>: 'nan' is not a number"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0.1" length="1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "unknown attribute 'length'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="cylinder" radius="0.1" length="1" span="6.3"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'span' of <shape> must be in (0, "},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="cylinder" radius="0.1" length="1" hollow="yes"/><shape link="world" type="ring" radius="0.01"/></contact></nscd>)" + tail, "attribute 'hollow' of <shape> must be 'true' or 'false', got 'yes'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="cylinder" radius="0.1" length="1" hollow="true"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "a hollow cylinder pairs only with a ring, not a plane"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="ring" radius="0.1" hollow="true"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "unknown attribute 'hollow'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="face" size="1 0"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "attribute 'size' of <shape> type 'face' must be 2 numbers > 0"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="face" size="1 2 3"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "expected 2 numbers, got '1 2 3'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="face" size="1 x"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "'x' is not a number"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="face"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "missing attribute 'size'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="face" size="1 1" radius="1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "unknown attribute 'radius'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="0.1" span="1"/><shape link="world" type="plane"/></contact></nscd>)" + tail, "unknown attribute 'span'"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c"><shape link="b" type="sphere" radius="0.1"/><shape link="world" type="face" size="1 1"/></contact></nscd>)" + tail, "sphere-face pairs are not supported (supported: "},
      {std::string(kHead) + fl + R"(<nscd><contact name="c" mu="-1">)" + sph + R"(</contact></nscd>)" + tail, "'mu' of <contact>"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c" e="2">)" + sph + R"(</contact></nscd>)" + tail, "'e' of <contact>"},
      {std::string(kHead) + fl + R"(<nscd><contact name="c" colour="red">)" + sph + R"(</contact></nscd>)" + tail, "unknown attribute 'colour'"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="linear" stiffness="-1"><end link="world"/><end link="b"/></spring></nscd>)" + tail, "'stiffness'"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="linear" stiffness="1" damping="-1"><end link="world"/><end link="b"/></spring></nscd>)" + tail, "'damping'"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="linear" stiffness="1" rest_length="-1"><end link="world"/><end link="b"/></spring></nscd>)" + tail, "'rest_length'"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="linear" stiffness="1"><end link="world"/></spring></nscd>)" + tail, "exactly two <end>"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="linear" stiffness="1"><end link="world"/><end link="b"/></spring><spring name="s" type="linear" stiffness="1"><end link="world"/><end link="b"/></spring></nscd>)" + tail, "duplicate spring name 's'"},
      {std::string(kHead) + pr + R"(<nscd><spring name="s" type="torsion" joint="j" stiffness="1"/></nscd>)" + tail, "needs a revolute or continuous joint"},
      {std::string(kHead) + fl + R"(<nscd><spring name="s" type="coil" stiffness="1"/></nscd>)" + tail, "unknown type 'coil'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="force" link="world" direction="1 0 0"/></nscd>)" + tail, "is ground"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="prescribed" link="b" joint="j" axis="1 0 0"/></nscd>)" + tail, "not both"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="prescribed"/></nscd>)" + tail, "needs attribute 'link' or 'joint'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="position"/></nscd>)" + tail, "needs attribute 'joint'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="position" joint="j" kp="-1"/></nscd>)" + tail, "'kp'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="position" joint="j"/><actuator name="a" type="position" joint="j"/></nscd>)" + tail, "duplicate actuator name 'a'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="prescribed" link="b" axis="0 0 0"/></nscd>)" + tail, "axis must be non-zero"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="prescribed" link="b" axis="1 0 0" constrain="x"/></nscd>)" + tail, "actuator 'a': constrain must be 'all' (the other 5 DOF fixed) or 'axis' (only the translation along axis prescribed), not 'x'"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="prescribed" joint="j" constrain="axis"/></nscd>)" + tail, "actuator 'a': 'constrain' applies to link= only"},
      {std::string(kHead) + rv + R"(<nscd><actuator name="a" type="force" link="b" direction="1 0 0" constrain="axis"/></nscd>)" + tail, "unknown attribute 'constrain'"},
      {std::string(kHead) + rv + R"(<nscd foo="1"/>)" + tail, "unknown attribute 'foo' on <nscd>"},
      {std::string(kHead) + rv + R"(<nscd><simulation dt="1e-4"/><simulation dt="1e-4"/></nscd>)" + tail, "more than one <simulation>"},
      {std::string(kHead) + rv + R"(<nscd><simulation theta="0.4"/></nscd>)" + tail, "'theta'"},
      {std::string(kHead) + rv + R"(<nscd><simulation gravity="0 0"/></nscd>)" + tail, "'gravity'"},
      {std::string(kHead) + rv + R"(<nscd><simulation max_iterations="0"/></nscd>)" + tail, "'max_iterations'"},
      {std::string(kHead) + rv + R"(<nscd><simulation planar="yz"/></nscd>)" + tail, "'planar'"},
      {"<robot name=\"x\"><link name=\"a\"/><link name=\"a\"/></robot>", "duplicate link name 'a'"},
      {"<robot name=\"x\"><link name=\"a\"/><link name=\"b\"/></robot>", "more than one root link"},
      {"<robot name=\"x\"><link name=\"a\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"q\"/></joint></robot>", "unknown link 'q'"},
      {"<robot name=\"x\"><link name=\"a\"><nscd/></link></robot>", "directly under <robot>"},
  };
  for (const auto& c : cases) {
    const std::string msg = errorOfString(c.first);
    EXPECT_EQ(msg.rfind("mem.urdf:", 0), 0u) << msg;
    EXPECT_NE(msg.find(c.second), std::string::npos) << "wanted '" << c.second << "', got: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_EQ(errorOfString("  \n", "desc"), "desc: empty scene");
}

// Whatever the damage, the loader either loads or throws SceneError naming the source.
TEST(SceneLoaderBad, NeverCrashesOnDamagedScenes) {
  uint32_t rng = 12345;
  auto next = [&] { return rng = rng * 1664525u + 1013904223u; };
  const char junk[] = "<>/\"= x0.-e9nan";
  int loaded = 0, refused = 0;
  for (const char* f : {"ball", "fourbar", "journal", "spring_mass"}) {
    const std::string text = slurp(scenePath(std::string("urdf/") + f + ".urdf"));
    for (size_t cut = 0; cut < text.size(); cut += 37) {
      for (int variant = 0; variant < 2; ++variant) {
        std::string t = variant == 0 ? text.substr(0, cut) : text;
        if (variant == 1) t[cut] = junk[next() % (sizeof(junk) - 1)];
        try {
          loadSceneFromString(t, "damaged");
          ++loaded;
        } catch (const SceneError& e) {
          ++refused;
          EXPECT_EQ(std::string(e.what()).rfind("damaged", 0), 0u) << e.what();
          EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
        }
      }
    }
  }
  EXPECT_GT(refused, 100);
  EXPECT_GT(loaded, 0);
}

// ------------------------------------------------------------------ settings

TEST(Settings, ApplySettingEveryKey) {
  Settings s;
  auto set = [&](const std::string& k, const std::string& v) { applySetting(s, SettingOverride{k, v, "--set"}); };
  set("dt", "2e-5");
  set("theta", "0.75");
  set("gravity", "0 -9.81 0");
  set("tolerance", "1e-6");
  set("max_iterations", "50");
  set("projection", "false");
  set("projection_tolerance", "1e-7");
  set("projection_max_iterations", "0");
  set("activation_gamma", "1");
  set("planar", "xy");
  EXPECT_DOUBLE_EQ(s.dt, 2e-5);
  EXPECT_DOUBLE_EQ(s.theta, 0.75);
  EXPECT_LT((s.gravity - Vec3(0, -9.81, 0)).norm(), kTight);
  EXPECT_DOUBLE_EQ(s.tolerance, 1e-6);
  EXPECT_EQ(s.max_iterations, 50);
  EXPECT_FALSE(s.projection);
  EXPECT_DOUBLE_EQ(s.projection_tolerance, 1e-7);
  EXPECT_EQ(s.projection_max_iterations, 0);
  EXPECT_DOUBLE_EQ(s.activation_gamma, 1.0);
  EXPECT_EQ(s.planar, PlanarMode::XY);
  set("planar", "false");
  EXPECT_EQ(s.planar, PlanarMode::None);
  set("planar", "true");
  EXPECT_EQ(s.planar, PlanarMode::XY);
  set("planar", "none");
  EXPECT_EQ(s.planar, PlanarMode::None);
  set("gravity", "[1, 2, 3]");
  EXPECT_LT((s.gravity - Vec3(1, 2, 3)).norm(), kTight);
  set("dt", "0.1");  // the upper bound is allowed
  EXPECT_DOUBLE_EQ(s.dt, 0.1);
  set("activation_margin", "1e-3");
  EXPECT_DOUBLE_EQ(s.activation_margin, 1e-3);
  set("contact_prediction", "0");
  EXPECT_DOUBLE_EQ(s.contact_prediction, 0.0);
  set("contact_prediction", "0.5");
  EXPECT_DOUBLE_EQ(s.contact_prediction, 0.5);
  EXPECT_EQ(s.joint_work, JointWork::None);
  set("joint_work", "moreau");
  EXPECT_EQ(s.joint_work, JointWork::Moreau);
  set("joint_work", "none");
  EXPECT_EQ(s.joint_work, JointWork::None);
  EXPECT_EQ(s.max_step_halvings, 8);
  set("max_step_halvings", "0");
  EXPECT_EQ(s.max_step_halvings, 0);
  set("max_step_halvings", "20");
  EXPECT_EQ(s.max_step_halvings, 20);
  EXPECT_EQ(s.step_control, StepControl::Fixed);
  set("step_control", "adaptive");
  EXPECT_EQ(s.step_control, StepControl::Adaptive);
  set("rtol", "1e-5");
  EXPECT_DOUBLE_EQ(s.rtol, 1e-5);
  set("atol", "1e-8");
  EXPECT_DOUBLE_EQ(s.atol, 1e-8);
  set("dt_min", "1e-10");
  EXPECT_DOUBLE_EQ(s.dt_min, 1e-10);
  set("max_order", "3");
  EXPECT_EQ(s.max_order, 3);
  EXPECT_EQ(settingKeys().size(), 19u);
}

TEST(Settings, ApplySettingRefusesBadValues) {
  const std::pair<std::string, std::string> bad[] = {
      {"dt", "0"},        {"dt", "-1e-4"},        {"dt", "0.2"},           {"dt", "nan"},
      {"dt", "abc"},      {"dt", ""},             {"theta", "0.49"},       {"theta", "1.01"},
      {"tolerance", "-1e-8"}, {"tolerance", "0"}, {"tolerance", "1"},      {"max_iterations", "0"},
      {"max_iterations", "2.5"}, {"max_iterations", "20000000"},
      {"max_step_halvings", "-1"}, {"max_step_halvings", "21"}, {"max_step_halvings", "1.5"}, {"projection", "maybe"},
      {"projection_tolerance", "0"}, {"projection_max_iterations", "-1"},
      {"activation_gamma", "1.5"}, {"contact_prediction", "-0.1"}, {"contact_prediction", "1.5"},
      {"contact_prediction", "nan"}, {"gravity", "0 0"}, {"gravity", "0 0 inf"}, {"planar", "xz"}, {"joint_work", "some"},
      {"no_such_key", "1"}};
  for (const auto& b : bad) {
    Settings s;
    const Settings before = s;
    try {
      applySetting(s, SettingOverride{b.first, b.second, "--set"});
      ADD_FAILURE() << b.first << "=" << b.second << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("--set: ", 0), 0u) << e.what();
      EXPECT_NE(std::string(e.what()).find(b.first), std::string::npos) << e.what();
    }
    EXPECT_DOUBLE_EQ(s.dt, before.dt);  // unchanged on refusal
  }
  try {
    Settings s;
    applySetting(s, SettingOverride{"dtt", "1", "--set"});
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("known: dt, theta"), std::string::npos) << e.what();
  }
}

TEST(Settings, OverridesApplyAfterSimulationElement) {
  const std::string path = scenePath("urdf/ball.urdf");
  Model m = loadScene(path, {{"dt", "5e-5", "--set"}, {"gravity", "0 0 -1", "--set"}, {"dt", "2e-5", "--set"}});
  EXPECT_DOUBLE_EQ(m.settings.dt, 2e-5);  // in order: the last wins
  EXPECT_LT((m.settings.gravity - Vec3(0, 0, -1)).norm(), kTight);
  try {
    loadScene(path, {{"theta", "2", "--set"}});
    ADD_FAILURE() << "theta=2 accepted";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--set: setting 'theta'", 0), 0u) << e.what();
  }
}

TEST(Settings, YamlFlatNestedAndList) {
  const std::string flat = nscd_test::writeTemp("# comment\ndt: 2.0e-5\ngravity: \"0 0 -1.62\"\nplanar: xy\n", ".yaml");
  auto o = readSettingsYaml(flat);
  ASSERT_EQ(o.size(), 3u);
  EXPECT_EQ(o[0].key, "dt");
  EXPECT_EQ(o[0].origin, flat + ":2");
  EXPECT_EQ(o[2].origin, flat + ":4");
  Model m = loadScene(scenePath("urdf/ball.urdf"), o);
  EXPECT_DOUBLE_EQ(m.settings.dt, 2e-5);
  EXPECT_LT((m.settings.gravity - Vec3(0, 0, -1.62)).norm(), kTight);
  EXPECT_EQ(m.settings.planar, PlanarMode::XY);

  const std::string nested = nscd_test::writeTemp(
      "simulation:\n  theta: 1.0\n  gravity: [0, -9.81, 0]\nprojection: false\nmax_iterations: 77\n", ".yaml");
  o = readSettingsYaml(nested);
  ASSERT_EQ(o.size(), 4u);
  Settings s;
  for (const auto& x : o) applySetting(s, x);
  EXPECT_DOUBLE_EQ(s.theta, 1.0);
  EXPECT_LT((s.gravity - Vec3(0, -9.81, 0)).norm(), kTight);
  EXPECT_FALSE(s.projection);
  EXPECT_EQ(s.max_iterations, 77);

  EXPECT_TRUE(readSettingsYaml(nscd_test::writeTemp("", ".yaml")).empty());
  std::remove(flat.c_str());
  std::remove(nested.c_str());
}

TEST(Settings, YamlErrorsNameFileAndLine) {
  auto err = [](const std::string& p) {
    try {
      readSettingsYaml(p);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  const std::string bad = scenePath("test/scenes/bad/bad_settings.yaml");
  EXPECT_EQ(err(bad).rfind(bad + ":4: unknown setting 'time_step' (known: dt,", 0), 0u) << err(bad);
  const std::string malformed = scenePath("test/scenes/bad/malformed.yaml");
  EXPECT_EQ(err(malformed).rfind(malformed + ":4: YAML error", 0), 0u) << err(malformed);
  // A key with a line break is quoted back on one line (found by fuzz/settings_yaml_fuzzer.cpp).
  const std::string key = scenePath("test/scenes/bad/line_break_in_key.yaml");
  EXPECT_EQ(err(key), key + ":3: setting 'simula\\ntion': expected a value, got a mapping");
  const std::string range = nscd_test::writeTemp("theta: 0.5\n\ndt: 0\n", ".yaml");
  EXPECT_EQ(err(range).rfind(range + ":3: setting 'dt'", 0), 0u) << err(range);
  const std::string list = nscd_test::writeTemp("- dt\n- 1\n", ".yaml");
  EXPECT_EQ(err(list).rfind(list + ":1: expected a mapping", 0), 0u) << err(list);
  EXPECT_EQ(err("/nonexistent/x.yaml"), "/nonexistent/x.yaml: cannot read file");
  std::remove(range.c_str());
  std::remove(list.c_str());
}
