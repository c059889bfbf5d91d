// Unit tests of the node's message building (no ROS master): contact and
// clearance markers, contact messages, parameter strings.
#include <cmath>

#include <gtest/gtest.h>

#include "contact_markers.hpp"
#include "ros_conversions.hpp"

using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

namespace {

const Marker* find(const MarkerArray& a, const std::string& ns, int id) {
  for (const Marker& m : a.markers)
    if (m.ns == ns && m.id == id) return &m;
  return nullptr;
}

nscd::ContactReport report(const nscd::Vec3& point, const nscd::Vec3& normal, double fn,
                           const nscd::Vec3& ft, bool sliding) {
  nscd::ContactReport c;
  c.point = point;
  c.normal = normal;
  c.fn = fn;
  c.ft = ft;
  c.sliding = sliding;
  return c;
}

}  // namespace

TEST(ContactMarkers, ArrowsScaleWithForceAndSphereMarksPoint) {
  nscd_node::MarkerStyle style;
  style.frame = "world";
  style.force_scale = 0.01;
  style.size = 0.02;
  std::vector<nscd::ContactReport> contacts = {
      report({1, 2, 3}, {0, 0, 1}, 5.0, {0.0, -2.0, 0.0}, true),
      report({0, 0, 0}, {1, 0, 0}, 3.0, {0, 0, 0}, false)};
  MarkerArray a;
  nscd_node::buildContactMarkers(contacts, {}, style, ros::Time(7.0), a);

  ASSERT_FALSE(a.markers.empty());
  EXPECT_EQ(a.markers[0].action, Marker::DELETEALL);
  // 1 DELETEALL + (normal, tangential, point) + (normal, point): no zero-length arrow.
  EXPECT_EQ(a.markers.size(), 6u);

  const Marker* n0 = find(a, "normal_force", 0);
  ASSERT_TRUE(n0);
  EXPECT_EQ(n0->type, Marker::ARROW);
  EXPECT_EQ(n0->header.frame_id, "world");
  EXPECT_EQ(n0->header.stamp, ros::Time(7.0));
  ASSERT_EQ(n0->points.size(), 2u);
  EXPECT_DOUBLE_EQ(n0->points[0].z, 3.0);
  EXPECT_NEAR(n0->points[1].z - n0->points[0].z, 0.05, 1e-15);  // 5 N * 0.01 m/N
  EXPECT_NEAR(n0->points[1].x - n0->points[0].x, 0.0, 1e-15);

  const Marker* t0 = find(a, "tangential_force", 0);
  ASSERT_TRUE(t0);
  EXPECT_NEAR(t0->points[1].y - t0->points[0].y, -0.02, 1e-15);
  const Marker* n1 = find(a, "normal_force", 1);
  ASSERT_TRUE(n1);
  EXPECT_NEAR(n1->points[1].x - n1->points[0].x, 0.03, 1e-15);
  EXPECT_EQ(find(a, "tangential_force", 1), nullptr);
  // Normal green (not RViz's red of visuals without material), sliding
  // tangential differs from it.
  EXPECT_GT(n0->color.g, 0.5f);
  EXPECT_LT(n0->color.r, 0.5f);
  EXPECT_FALSE(t0->color.r == n0->color.r && t0->color.g == n0->color.g &&
               t0->color.b == n0->color.b);

  const Marker* p0 = find(a, "contact_point", 0);
  ASSERT_TRUE(p0);
  EXPECT_EQ(p0->type, Marker::SPHERE);
  EXPECT_DOUBLE_EQ(p0->pose.position.y, 2.0);
  EXPECT_DOUBLE_EQ(p0->scale.x, 0.02);
}

TEST(ContactMarkers, StickingAndSlidingColoursDiffer) {
  nscd_node::MarkerStyle style;
  MarkerArray a;
  nscd_node::buildContactMarkers({report({0, 0, 0}, {0, 0, 1}, 1, {1, 0, 0}, false),
                                  report({0, 0, 0}, {0, 0, 1}, 1, {1, 0, 0}, true)},
                                 {}, style, ros::Time(), a);
  const Marker* stick = find(a, "tangential_force", 0);
  const Marker* slide = find(a, "tangential_force", 1);
  ASSERT_TRUE(stick && slide);
  EXPECT_FALSE(stick->color.r == slide->color.r && stick->color.g == slide->color.g &&
               stick->color.b == slide->color.b);
}

TEST(ContactMarkers, EccentricityMagnifiedInBearingPlane) {
  nscd_node::MarkerStyle style;
  style.ecc_scale = 100;
  nscd_node::EccentricityView v;
  v.center = {1, 2, 3};
  v.axis = {0, 0, 1};
  v.ref = {1, 0, 0};
  v.radial = 1e-4;
  v.ecc = 0.5;
  v.angle = M_PI / 2;
  v.fn = 0;
  MarkerArray a;
  nscd_node::buildContactMarkers({}, {v}, style, ros::Time(), a);

  const Marker* line = find(a, "eccentricity", 0);
  ASSERT_TRUE(line);
  ASSERT_EQ(line->points.size(), 2u);
  // tip = centre + 0.5 * 1e-4 * 100 * (0, 1, 0)
  EXPECT_NEAR(line->points[1].x, 1.0, 1e-12);
  EXPECT_NEAR(line->points[1].y, 2.005, 1e-12);
  EXPECT_NEAR(line->points[1].z, 3.0, 1e-12);

  const Marker* circle = find(a, "clearance_limit", 0);
  ASSERT_TRUE(circle);
  ASSERT_GT(circle->points.size(), 8u);
  for (const auto& p : circle->points) {
    EXPECT_NEAR(std::hypot(p.x - 1.0, p.y - 2.0), 0.01, 1e-12);  // c_r * ecc_scale
    EXPECT_NEAR(p.z, 3.0, 1e-12);
  }
  // Free: cyan; in contact: another colour.
  const std_msgs::ColorRGBA free_color = line->color;
  v.fn = 2.0;
  nscd_node::buildContactMarkers({}, {v}, style, ros::Time(), a);
  EXPECT_NE(find(a, "eccentricity", 0)->color.g, free_color.g);
}

// The status text: sim time in ms to the microsecond, the rtf, the arrow scale
// in N per mm of arrow (force_scale 0.0003 m/N: 1 mm = 3.33 N), the figures.
TEST(ContactMarkers, StatusTextShowsTimeScaleAndFigures) {
  nscd_node::MarkerStyle style;
  style.force_scale = 0.0003;
  nscd_node::StatusText text;
  text.position = nscd::Vec3(0.01, -0.02, 0.005);
  text.height = 0.002;
  visualization_msgs::Marker m;
  nscd_node::buildStatusMarker(0.0051234, 0.001, style, {"C7.fn", "probe.effort"}, {13.25, 2.5}, text,
                    ros::Time(1.0), m);
  EXPECT_EQ(m.type, visualization_msgs::Marker::TEXT_VIEW_FACING);
  EXPECT_EQ(m.ns, "status");
  EXPECT_DOUBLE_EQ(m.pose.position.y, -0.02);
  EXPECT_DOUBLE_EQ(m.scale.z, 0.002);
  EXPECT_NE(m.text.find("t = 5.123 ms"), std::string::npos) << m.text;
  EXPECT_NE(m.text.find("rtf 0.001"), std::string::npos) << m.text;
  EXPECT_NE(m.text.find("1 mm = 3.33 N"), std::string::npos) << m.text;
  EXPECT_NE(m.text.find("C7.fn 13.250"), std::string::npos) << m.text;
  EXPECT_NE(m.text.find("probe.effort 2.500"), std::string::npos) << m.text;
}

TEST(RosConversions, ContactMessageNamesLinksAndSource) {
  nscd::Model model;
  model.world_frame = "world";
  model.bodies.resize(2);
  model.bodies[0].name = "ball";
  model.bodies[1].name = "arm";
  model.contacts.resize(1);
  model.contacts[0].name = "ground";
  model.clearance_joints.resize(1);
  model.clearance_joints[0].name = "J1";

  nscd::ContactReport r = report({1, 2, 3}, {0, 0, 1}, 4.0, {0.5, 0, 0}, true);
  r.body_a = 0;
  r.body_b = nscd::kGround;
  r.feature = 2;
  r.gap = -1e-6;
  nscd_sim::Contact c;
  nscd_node::toContactMsg(model, r, c);
  EXPECT_EQ(c.name, "ground");
  EXPECT_FALSE(c.clearance);
  EXPECT_EQ(c.link_a, "ball");
  EXPECT_EQ(c.link_b, "world");
  EXPECT_EQ(c.feature, 2u);
  EXPECT_EQ(c.normal_force, 4.0);
  EXPECT_EQ(c.tangential_force.x, 0.5);
  EXPECT_EQ(c.gap, -1e-6);
  EXPECT_TRUE(c.sliding);

  r.clearance = true;
  r.source = 0;
  r.body_b = 1;
  nscd_node::toContactMsg(model, r, c);
  EXPECT_EQ(c.name, "J1");
  EXPECT_TRUE(c.clearance);
  EXPECT_EQ(c.link_b, "arm");
}

TEST(RosConversions, TransformIsUnitQuaternion) {
  nscd::Pose p;
  p.p = {1, 2, 3};
  p.q = nscd::Quat(2, 0, 0, 0);  // not unit
  const geometry_msgs::Transform t = nscd_node::toTransform(p);
  EXPECT_EQ(t.translation.z, 3.0);
  EXPECT_DOUBLE_EQ(t.rotation.w, 1.0);
}

TEST(RosConversions, ParamStringsAsTheCommandLineWritesThem) {
  std::string s;
  EXPECT_TRUE(nscd_node::paramToString(XmlRpc::XmlRpcValue(1e-4), s));
  EXPECT_EQ(s, "0.0001");
  EXPECT_TRUE(nscd_node::paramToString(XmlRpc::XmlRpcValue(0.1), s));
  EXPECT_EQ(std::stod(s), 0.1);  // shortest form that reads back exactly
  EXPECT_TRUE(nscd_node::paramToString(XmlRpc::XmlRpcValue(200), s));
  EXPECT_EQ(s, "200");
  EXPECT_TRUE(nscd_node::paramToString(XmlRpc::XmlRpcValue(false), s));
  EXPECT_EQ(s, "false");
  EXPECT_TRUE(nscd_node::paramToString(XmlRpc::XmlRpcValue("xy"), s));
  EXPECT_EQ(s, "xy");

  XmlRpc::XmlRpcValue g;
  g[0] = 0.0;
  g[1] = 0;
  g[2] = -9.81;
  EXPECT_TRUE(nscd_node::paramToString(g, s));
  EXPECT_EQ(s, "0 0 -9.81");

  XmlRpc::XmlRpcValue nested;
  nested[0] = g;
  EXPECT_FALSE(nscd_node::paramToString(nested, s));
  XmlRpc::XmlRpcValue st;
  st["a"] = 1;
  EXPECT_FALSE(nscd_node::paramToString(st, s));
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
