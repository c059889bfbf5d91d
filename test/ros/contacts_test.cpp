// rostest: the node's ~contacts are the engine's numbers (compared with an
// in-process nscd::Simulator stepped the same number of times), and
// ~contact_markers shows them while contacts are active. Scenes: urdf/ball.urdf
// (contacts.test, impacts) and urdf/slope.urdf (contacts_slope.test, four
// sticking contact points with friction).
#include <atomic>
#include <cmath>

#include <gtest/gtest.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <visualization_msgs/MarkerArray.h>

#include "nscd_sim/ContactArray.h"
#include "nscd_sim/Step.h"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "ros_test_support.hpp"

using nscd_test::nodeTopic;
using visualization_msgs::Marker;
using visualization_msgs::MarkerArray;

namespace {

// Steps the node by `count` and returns the ~contacts message of the result (null,
// with a failure that says what the node answered, if it did not step or publish).
nscd_sim::ContactArrayConstPtr stepNode(uint32_t count, uint64_t expected_steps) {
  nscd_sim::Step step;
  step.request.count = count;
  const ::testing::AssertionResult called = nscd_test::callService(nodeTopic("step"), step);
  if (!called) {
    ADD_FAILURE() << "~step(" << count << "): " << called.message();
    return {};
  }
  if (!step.response.success || step.response.steps_taken != count) {
    ADD_FAILURE() << "~step(" << count << ") answered success " << int(step.response.success) << ", "
                  << step.response.steps_taken << " steps taken: " << step.response.message;
    return {};
  }
  // Steps, not wall time, say which publication: wait generously for it.
  const double timeout = 20.0;
  std::atomic<uint64_t> seen{0};
  auto msg = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"),
      [&](const nscd_sim::ContactArray& m) {
        seen = m.steps;
        return m.steps == expected_steps;
      },
      timeout);
  if (!msg)
    ADD_FAILURE() << "no ~contacts after step " << expected_steps << " within " << timeout
                  << " s (last seen: after step " << seen << ")";
  return msg;
}

// Same engine, same scene, same steps: the same numbers, bit for bit.
void expectSameContacts(const nscd::Simulator& sim, const nscd_sim::ContactArray& msg) {
  const nscd::Model& model = sim.model();
  EXPECT_EQ(msg.sim_time, sim.state().t);
  EXPECT_EQ(msg.header.frame_id, model.world_frame);
  ASSERT_EQ(msg.contacts.size(), sim.contactPoints().size());
  for (size_t i = 0; i < msg.contacts.size(); ++i) {
    const nscd::ContactReport& r = sim.contactPoints()[i];
    const nscd_sim::Contact& c = msg.contacts[i];
    EXPECT_EQ(c.clearance, r.clearance);
    EXPECT_EQ(c.name, r.clearance ? model.clearance_joints[r.source].name
                                  : model.contacts[r.source].name);
    EXPECT_EQ(c.feature, static_cast<uint32_t>(r.feature));
    EXPECT_EQ(c.normal_force, r.fn);
    EXPECT_EQ(c.tangential_force.x, r.ft.x());
    EXPECT_EQ(c.tangential_force.y, r.ft.y());
    EXPECT_EQ(c.tangential_force.z, r.ft.z());
    EXPECT_EQ(c.point.x, r.point.x());
    EXPECT_EQ(c.point.y, r.point.y());
    EXPECT_EQ(c.point.z, r.point.z());
    EXPECT_EQ(c.normal.x, r.normal.x());
    EXPECT_EQ(c.normal.y, r.normal.y());
    EXPECT_EQ(c.normal.z, r.normal.z());
    EXPECT_EQ(c.gap, r.gap);
    EXPECT_EQ(c.sliding, r.sliding);
  }
}

const Marker* findMarker(const MarkerArray& a, const std::string& ns, int id) {
  for (const Marker& m : a.markers)
    if (m.ns == ns && m.id == id && m.action == Marker::ADD) return &m;
  return nullptr;
}

int countNamespace(const MarkerArray& a, const std::string& ns) {
  int n = 0;
  for (const Marker& m : a.markers) n += (m.ns == ns && m.action == Marker::ADD);
  return n;
}

}  // namespace

// Steps to the first active contact (at least 20 steps), then one step at a time
// (a bouncing ball loses it), then to the next active contact, in the node
// (~step) and in-process, comparing every field of every contact each time.
// Leaves the node paused with active contacts.
TEST(Contacts, ForcesEqualInProcessSimulator) {
  nscd::Simulator sim(nscd::loadScene(nscd_test::sceneParam()));
  uint64_t steps = 0;
  auto stepUntilContact = [&](uint32_t at_least) {
    uint32_t n = 0;
    while ((n < at_least || sim.contactPoints().empty()) && n < 200000) {
      if (sim.step() == nscd::StepStatus::NonFinite) break;
      ++n;
    }
    return n;
  };

  uint32_t n = stepUntilContact(20);
  ASSERT_FALSE(sim.contactPoints().empty()) << "no contact within 200000 steps";
  steps += n;
  auto msg = stepNode(n, steps);
  ASSERT_TRUE(msg);
  expectSameContacts(sim, *msg);
  double fn = 0;
  for (const auto& c : msg->contacts) fn += c.normal_force;
  EXPECT_GT(fn, 0.0);

  for (int i = 0; i < 3; ++i) {
    sim.step();
    msg = stepNode(1, ++steps);
    ASSERT_TRUE(msg);
    expectSameContacts(sim, *msg);
  }

  n = stepUntilContact(0);
  ASSERT_FALSE(sim.contactPoints().empty());
  if (n > 0) {
    steps += n;
    msg = stepNode(n, steps);
    ASSERT_TRUE(msg);
    expectSameContacts(sim, *msg);
  }
}

// Paused with active contacts (previous test): per contact a normal-force arrow
// fn * force_scale along the normal, a friction arrow ft * force_scale (none if
// ft is zero), and a sphere at the point.
TEST(Contacts, MarkersAppearWhileContactsActive) {
  auto contacts = nscd_test::waitForMessage<nscd_sim::ContactArray>(nodeTopic("contacts"), 20.0);
  ASSERT_TRUE(contacts) << "no ~contacts within 20 s";
  ASSERT_FALSE(contacts->contacts.empty()) << "run after ForcesEqualInProcessSimulator";
  double force_scale = 0, size = 0;
  ASSERT_TRUE(ros::param::get(nodeTopic("force_scale"), force_scale));
  ASSERT_TRUE(ros::param::get(nodeTopic("marker_size"), size));

  auto markers = nscd_test::waitForMessage<MarkerArray>(
      nodeTopic("contact_markers"),
      [](const MarkerArray& a) { return countNamespace(a, "contact_point") > 0; }, 20.0);
  ASSERT_TRUE(markers) << "no ~contact_markers with a contact_point within 20 s";
  ASSERT_FALSE(markers->markers.empty());
  EXPECT_EQ(markers->markers[0].action, Marker::DELETEALL);
  EXPECT_EQ(countNamespace(*markers, "contact_point"),
            static_cast<int>(contacts->contacts.size()));
  auto expectArrow = [&](const Marker* arrow, const geometry_msgs::Point& from, double x,
                         double y, double z) {
    ASSERT_TRUE(arrow);
    ASSERT_EQ(arrow->type, Marker::ARROW);
    ASSERT_EQ(arrow->points.size(), 2u);
    EXPECT_DOUBLE_EQ(arrow->points[0].x, from.x);
    EXPECT_DOUBLE_EQ(arrow->points[0].y, from.y);
    EXPECT_DOUBLE_EQ(arrow->points[0].z, from.z);
    EXPECT_NEAR(arrow->points[1].x - from.x, x, 1e-12);
    EXPECT_NEAR(arrow->points[1].y - from.y, y, 1e-12);
    EXPECT_NEAR(arrow->points[1].z - from.z, z, 1e-12);
  };
  for (size_t i = 0; i < contacts->contacts.size(); ++i) {
    const nscd_sim::Contact& c = contacts->contacts[i];
    const int id = static_cast<int>(i);
    const Marker* point = findMarker(*markers, "contact_point", id);
    ASSERT_TRUE(point);
    EXPECT_EQ(point->type, Marker::SPHERE);
    EXPECT_DOUBLE_EQ(point->pose.position.x, c.point.x);
    EXPECT_DOUBLE_EQ(point->pose.position.y, c.point.y);
    EXPECT_DOUBLE_EQ(point->pose.position.z, c.point.z);
    const double k = force_scale * c.normal_force;
    if (k > 1e-3 * size)
      expectArrow(findMarker(*markers, "normal_force", id), c.point, k * c.normal.x,
                  k * c.normal.y, k * c.normal.z);
    const auto& ft = c.tangential_force;
    if (force_scale * std::sqrt(ft.x * ft.x + ft.y * ft.y + ft.z * ft.z) > 1e-3 * size)
      expectArrow(findMarker(*markers, "tangential_force", id), c.point, force_scale * ft.x,
                  force_scale * ft.y, force_scale * ft.z);
    else
      EXPECT_EQ(findMarker(*markers, "tangential_force", id), nullptr);
  }
}

// No contact, no contact markers: after ~reset the ball hangs in the air.
TEST(Contacts, NoMarkersWithoutContacts) {
  std_srvs::Empty reset;
  ASSERT_TRUE(nscd_test::callService(nodeTopic("reset"), reset));
  auto contacts = nscd_test::waitForMessage<nscd_sim::ContactArray>(
      nodeTopic("contacts"), [](const nscd_sim::ContactArray& m) { return m.steps == 0; }, 20.0);
  ASSERT_TRUE(contacts) << "no ~contacts of step 0 within 20 s after ~reset";
  EXPECT_TRUE(contacts->contacts.empty());
  // Markers of the same or a later publication (same stamp as ~contacts).
  auto markers = nscd_test::waitForMessage<MarkerArray>(
      nodeTopic("contact_markers"),
      [&](const MarkerArray& a) {
        return !a.markers.empty() && a.markers[0].header.stamp >= contacts->header.stamp;
      },
      20.0);
  ASSERT_TRUE(markers) << "no ~contact_markers as new as the ~contacts of the reset within 20 s";
  ASSERT_EQ(markers->markers.size(), 1u);  // only the DELETEALL
  EXPECT_EQ(markers->markers[0].action, Marker::DELETEALL);
}

int main(int argc, char** argv) { return nscd_test::runRosTestNode(argc, argv, "contacts_test"); }
