// Unit tests of the node's message building (no ROS master): contact and
// clearance markers, contact messages, parameter strings.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "contact_markers.hpp"
#include "label_layout.hpp"
#include "ros_conversions.hpp"
#include "run_events.hpp"

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
  nscd_node::buildStatusMarker(0.0051234, 0.001, false, style, {"C7.fn", "probe.effort"}, {13.25, 2.5}, text,
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
  EXPECT_NE(m.text.find("eccentricity x50"), std::string::npos) << m.text;  // MarkerStyle's default
  // Paused, the rtf (0 over the last period) gives way to "paused".
  nscd_node::buildStatusMarker(0.0051234, 0.0, true, style, {"C7.fn"}, {13.25}, text, ros::Time(1.0), m);
  EXPECT_NE(m.text.find("t = 5.123 ms   paused"), std::string::npos) << m.text;
  EXPECT_EQ(m.text.find("rtf"), std::string::npos) << m.text;
  EXPECT_NE(m.text.find("1 mm = 3.33 N"), std::string::npos) << m.text;
}

// Labels: one per named contact with a force (its summed force, at the tip of its
// largest arrow, past it along the normal), one per clearance joint; none when off.
// marker_z lifts the eccentricity markers and labels; a stand-in joint (c_r >= r_j)
// gets no ring.
TEST(ContactMarkers, LabelsNameContactsAndJointsAndMarkerZLifts) {
  nscd_node::MarkerStyle style;
  style.force_scale = 0.001;
  style.size = 0.001;
  style.labels = true;
  style.label_size = 0.002;
  style.have_marker_z = true;
  style.marker_z = 0.05;
  std::vector<nscd::ContactReport> contacts = {report({0, 0, 0}, {0, 1, 0}, 2.0, {0, 0, 0}, false),
                                               report({0.01, 0, 0}, {0, 1, 0}, 5.0, {0, 0, 0}, false),
                                               report({0.02, 0, 0}, {1, 0, 0}, 0.0, {0, 0, 0}, false)};
  contacts[0].source = contacts[1].source = 1;  // two points of "C4_3"
  contacts[2].source = 0;                        // "C7", open: no label
  nscd_node::EccentricityView j4, stand_in;
  j4.center = {0, 0.03, 0.001};
  j4.radial = 1e-4;
  j4.journal_radius = 1e-3;
  j4.ecc = 1;
  j4.angle = 0;
  j4.fn = 3.5;
  j4.name = "J4";
  stand_in.radial = 1;
  stand_in.journal_radius = 1e-3;
  stand_in.name = "P3_axis";
  nscd_node::MarkerNames names;
  names.contacts = {"C7", "C4_3"};
  names.clearance = {"J4", "P3_axis"};
  MarkerArray a;
  nscd_node::buildContactMarkers(contacts, {j4, stand_in}, style, ros::Time(), a, names);

  const Marker* c4 = find(a, "contact_label", 1);
  ASSERT_TRUE(c4);
  EXPECT_EQ(c4->type, Marker::TEXT_VIEW_FACING);
  EXPECT_EQ(c4->text, "C4_3 7.00 N");
  EXPECT_NEAR(c4->pose.position.x, 0.01, 1e-12);                 // at the 5 N point
  EXPECT_NEAR(c4->pose.position.y, 0.005 + 0.7 * 0.002, 1e-12);  // past its arrow's tip
  EXPECT_DOUBLE_EQ(c4->pose.position.z, 0.05);
  EXPECT_DOUBLE_EQ(c4->scale.z, 0.002);
  EXPECT_FALSE(find(a, "contact_label", 0)) << "an open contact is labelled";

  const Marker* j4_label = find(a, "clearance_label", 0);
  ASSERT_TRUE(j4_label);
  EXPECT_EQ(j4_label->text, "J4 3.50 N");
  // Opposite the eccentricity (+x), its box just outside the magnified ring (1e-4 * 50
  // = 5 mm), half a text height away.
  EXPECT_NEAR(j4_label->pose.position.x,
              -(0.005 + 0.5 * 0.002 + nscd_node::labelBox("J4 3.50 N", 0.002).half_width), 1e-12);
  EXPECT_NEAR(j4_label->pose.position.y, 0.03, 1e-12);
  const Marker* arrow = find(a, "eccentricity", 0);
  ASSERT_TRUE(arrow);
  EXPECT_EQ(arrow->type, Marker::ARROW);
  EXPECT_DOUBLE_EQ(arrow->points[0].z, 0.05);
  EXPECT_NEAR(arrow->points[1].x, 0.005, 1e-12);
  EXPECT_DOUBLE_EQ(find(a, "clearance_limit", 0)->points[0].z, 0.05);
  EXPECT_FALSE(find(a, "clearance_limit", 1)) << "the stand-in joint's 50 m ring is drawn";
  EXPECT_FALSE(find(a, "clearance_label", 1));

  // A journal far outside its clearance: the arrow stops at 1.5 ring radii, the
  // label gives the eccentricity.
  j4.ecc = 800;
  nscd_node::buildContactMarkers({}, {j4}, style, ros::Time(), a, names);
  EXPECT_NEAR(find(a, "eccentricity", 0)->points[1].x, 1.5 * 0.005, 1e-12);
  EXPECT_EQ(find(a, "clearance_label", 0)->text, "J4 3.50 N (e = 800 c_r)");
  j4.ecc = 1;

  style.labels = false;
  style.have_marker_z = false;
  nscd_node::buildContactMarkers(contacts, {j4}, style, ros::Time(), a, names);
  EXPECT_FALSE(find(a, "contact_label", 1));
  EXPECT_FALSE(find(a, "clearance_label", 0));
  EXPECT_DOUBLE_EQ(find(a, "eccentricity", 0)->points[0].z, 0.001);  // at the bearing
}

// Bearings as close as the C-60's (J3, J4, J6 a few mm apart, J2, J7 and S3 on one
// axis; rings c_r x 40, labels 1.2 mm high, all in contact): no two labels overlap
// and no label covers a ring (boxes of labelBox, checked here independently of the
// layout's own sums), each stays within three text heights of its ring. Placed
// opposite the eccentricity as before the layout, they would overlap.
TEST(ContactMarkers, CrowdedBearingLabelsDoNotOverlap) {
  nscd_node::MarkerStyle style;
  style.labels = true;
  style.label_size = 0.0012;
  style.ecc_scale = 40;
  style.have_marker_z = true;
  style.marker_z = 0.03;
  struct J { const char* name; double x, y, ring, angle; };
  const J joints[] = {{"J1", -16.1, 10.0, 3.4, 2.9}, {"J2", 0, 0, 2.0, 0.3},     {"J3", 7.77, 7.64, 2.4, 0.1},
                      {"J4", 7.0, -0.25, 2.4, 2.0},  {"J5", -11.66, 8.47, 1.8, -0.2}, {"J6", 4.87, 6.88, 1.8, 3.3},
                      {"J7", 0, 0, 2.2, 1.0},        {"S3", 0, 0, 0.24, -2.5}};
  std::vector<nscd_node::EccentricityView> views;
  for (const J& j : joints) {
    nscd_node::EccentricityView v;
    v.center = {1e-3 * j.x, 1e-3 * j.y, 0.005};
    v.radial = 1e-3 * j.ring / 40;
    v.journal_radius = 1e-3;
    v.ecc = 1;
    v.angle = j.angle;
    v.fn = 39.59;
    v.name = j.name;
    views.push_back(v);
  }
  MarkerArray a;
  nscd_node::buildContactMarkers({}, views, style, ros::Time(), a);
  const double h = style.label_size;
  struct Placed { double x, y, hw, hh; };
  std::vector<Placed> placed, before;
  for (size_t i = 0; i < views.size(); ++i) {
    const Marker* m = find(a, "clearance_label", static_cast<int>(i));
    ASSERT_TRUE(m) << joints[i].name;
    const nscd_node::LabelBox b = nscd_node::labelBox(m->text, h);
    placed.push_back({m->pose.position.x, m->pose.position.y, b.half_width, b.half_height});
    EXPECT_DOUBLE_EQ(m->pose.position.z, 0.03);
    const double r = views[i].radial * style.ecc_scale;
    const double reach = std::hypot(b.half_width, b.half_height);
    EXPECT_LT(std::hypot(m->pose.position.x - views[i].center.x(), m->pose.position.y - views[i].center.y()),
              r + 0.5 * h + reach + 3.0 * h + 1e-12) << joints[i].name << " strayed from its ring";
    // The place the label had before the layout: outside the ring opposite the arrow.
    before.push_back({views[i].center.x() - (r + 1.2 * h) * std::cos(joints[i].angle),
                      views[i].center.y() - (r + 1.2 * h) * std::sin(joints[i].angle), b.half_width, b.half_height});
  }
  auto overlapping = [](const Placed& p, const Placed& q) {
    return std::abs(p.x - q.x) < p.hw + q.hw - 1e-12 && std::abs(p.y - q.y) < p.hh + q.hh - 1e-12;
  };
  int pairs_before = 0;
  for (size_t i = 0; i < placed.size(); ++i)
    for (size_t k = i + 1; k < placed.size(); ++k) {
      EXPECT_FALSE(overlapping(placed[i], placed[k])) << joints[i].name << " and " << joints[k].name << " overlap";
      pairs_before += overlapping(before[i], before[k]);
    }
  EXPECT_GE(pairs_before, 2) << "the fixture is not crowded";
  for (size_t i = 0; i < placed.size(); ++i)
    for (size_t k = 0; k < views.size(); ++k) {
      // The nearest point of the box to the ring's centre lies outside the ring.
      const Placed& p = placed[i];
      const double dx = std::max({p.x - p.hw - views[k].center.x(), 0.0, views[k].center.x() - p.x - p.hw});
      const double dy = std::max({p.y - p.hh - views[k].center.y(), 0.0, views[k].center.y() - p.y - p.hh});
      EXPECT_GE(std::hypot(dx, dy), views[k].radial * style.ecc_scale - 1e-12)
          << joints[i].name << "'s label covers the ring of " << joints[k].name;
    }
}

TEST(ContactMarkers, EventLabelsListedUnderTheStatusText) {
  nscd_node::MarkerStyle style;
  nscd_node::StatusText text;
  text.position = nscd::Vec3(0.01, -0.02, 0.005);
  text.height = 0.002;
  MarkerArray a;
  nscd_node::appendEventMarkers({{"latch released", 0.00843}, {"C7 open", 0.0098765}}, style, text,
                                ros::Time(), a);
  ASSERT_EQ(a.markers.size(), 2u);
  EXPECT_EQ(a.markers[0].ns, "events");
  EXPECT_EQ(a.markers[0].text, "latch released  t = 8.430 ms");
  EXPECT_EQ(a.markers[1].text, "C7 open  t = 9.877 ms");
  EXPECT_LT(a.markers[0].pose.position.y, -0.02 - 5 * 0.002);  // below the two status lines
  EXPECT_LT(a.markers[1].pose.position.y, a.markers[0].pose.position.y - 0.002);
}

// Event definitions: a figure or a BASE*.SUFFIX group (BASE and BASE_*), > or <,
// a number; each malformed form is refused with a message saying what is wrong.
TEST(RunEvents, DefinitionsParseGroupsAndRefuseMalformed) {
  const std::vector<std::string> names = {"J1.q", "C4.gap", "C4.fn", "C4_2.gap", "C4_F1.gap", "C40.gap",
                                          "C7.gap", "probe.effort"};
  nscd_node::EventDefinition d;
  std::string err;
  ASSERT_TRUE(nscd_node::parseEventDefinition("latch released: C4*.gap > 2e-5", names, d, err)) << err;
  EXPECT_EQ(d.label, "latch released");
  EXPECT_EQ(d.figures, (std::vector<int>{1, 3, 4}));  // not C4.fn, not C40.gap
  EXPECT_TRUE(d.greater);
  EXPECT_DOUBLE_EQ(d.threshold, 2e-5);
  ASSERT_TRUE(nscd_node::parseEventDefinition("probe free:probe.effort<0.1", names, d, err)) << err;
  EXPECT_EQ(d.figures, (std::vector<int>{7}));
  EXPECT_FALSE(d.greater);
  struct Bad { const char* text; const char* says; };
  for (const Bad& b : {Bad{"C7.gap > 1e-4", "no ':'"}, Bad{": C7.gap > 1", "empty label"},
                       Bad{"x: C7.gap = 1", "no '<' or '>'"}, Bad{"x: C7.gap > abc", "not a number"},
                       Bad{"x: C9.gap > 1", "no key figure 'C9.gap'"}, Bad{"x: C4*gap > 1", "a group is"},
                       Bad{"x: C4*.gap > inf", "not a number"}}) {
    EXPECT_FALSE(nscd_node::parseEventDefinition(b.text, names, d, err)) << b.text;
    EXPECT_NE(err.find(b.says), std::string::npos) << b.text << " -> " << err;
    EXPECT_NE(err.find("expected \"LABEL: FIGURE > VALUE\""), std::string::npos ) << err;
  }
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

// toPose copies the pose as it is; fromPose (an interactive marker's feedback)
// gives a unit quaternion, the identity when the message's has no finite length.
TEST(RosConversions, PosesBothWays) {
  nscd::Pose p;
  p.p = {1, -2, 3};
  p.q = nscd::Quat(Eigen::AngleAxisd(0.3, nscd::Vec3::UnitZ()));
  const geometry_msgs::Pose m = nscd_node::toPose(p);
  EXPECT_EQ(m.position.y, -2.0);
  EXPECT_EQ(m.orientation.z, p.q.z());
  const nscd::Pose back = nscd_node::fromPose(m);
  EXPECT_EQ(back.p, p.p);
  EXPECT_NEAR(back.q.angularDistance(p.q), 0.0, 1e-15);
  geometry_msgs::Pose bad = m;
  bad.orientation.w = bad.orientation.x = bad.orientation.y = bad.orientation.z = 0;
  EXPECT_TRUE(nscd_node::fromPose(bad).q.isApprox(nscd::Quat::Identity()));
  for (const double x : {double(NAN), double(INFINITY), 1e300}) {  // 1e300: the norm overflows
    bad.orientation.w = x;
    const nscd::Quat q = nscd_node::fromPose(bad).q;
    EXPECT_TRUE(q.coeffs().allFinite()) << x;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15) << x;
  }
  const std_msgs::ColorRGBA c = nscd_node::rgba(0.1f, 0.2f, 0.3f);
  EXPECT_EQ(c.b, 0.3f);
  EXPECT_EQ(c.a, 1.0f);
}

// Numbers in parameters: integers and finite doubles; NaN, inf, strings, booleans
// and lists are not numbers (the caller warns or refuses, the output untouched).
TEST(RosConversions, ParamNumberTakesFiniteIntegersAndDoubles) {
  double x = -7;
  EXPECT_TRUE(nscd_node::paramNumber(XmlRpc::XmlRpcValue(3), x));
  EXPECT_EQ(x, 3.0);
  EXPECT_TRUE(nscd_node::paramNumber(XmlRpc::XmlRpcValue(-0.25), x));
  EXPECT_EQ(x, -0.25);
  XmlRpc::XmlRpcValue list;
  list[0] = 1.0;
  for (const XmlRpc::XmlRpcValue& v : {XmlRpc::XmlRpcValue(NAN), XmlRpc::XmlRpcValue(INFINITY),
                                      XmlRpc::XmlRpcValue(-INFINITY), XmlRpc::XmlRpcValue("1.5"),
                                      XmlRpc::XmlRpcValue(true), list, XmlRpc::XmlRpcValue()}) {
    EXPECT_FALSE(nscd_node::paramNumber(v, x));
    EXPECT_EQ(x, -0.25) << "written on a refusal";
  }
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
