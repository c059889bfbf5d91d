// A link-prescribed actuator with constrain="axis": only the body's translation
// along the axis follows the command; its other 5 DOF are free. Checked against
// closed forms: a body driven along x falls freely in y under gravity and spins
// about x under a torque; a rod driven along x through a bore (two rings inside a
// hollow cylinder, the C-60's plunger bearing in small) drops by the radial gap,
// rests on the bore and the drive's effort is the Coulomb friction mu m g.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

constexpr double kMass = 0.5;    // kg
constexpr double kIxx = 1e-4;    // kg m^2, about the drive axis
constexpr double kDt = 1e-4;     // s
constexpr double kSpeed = 0.1;   // m/s, the commanded ramp

// A rod along x (0.5 kg) placed floating at (0, 0, 0.3), turned 90 deg about z in
// its link frame so that the actuator's link-frame axis "0 -1 0" is world +x (the
// axis is converted at the initial pose). `extra` goes into <nscd>.
std::string rodScene(const std::string& gravity, const std::string& constrain, const std::string& extra) {
  return R"(<?xml version="1.0"?>
<robot name="rod">
  <link name="world"/>
  <link name="rod">
    <inertial><origin xyz="0 0 0"/><mass value="0.5"/>
      <inertia ixx="2e-3" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="2e-3"/></inertial>
  </link>
  <joint name="place" type="floating"><parent link="world"/><child link="rod"/>
    <origin xyz="0 0 0.3" rpy="0 0 1.5707963267948966"/></joint>
  <nscd>
    <actuator name="drive" type="prescribed" link="rod" axis="0 -1 0")" + constrain + R"(/>
    <actuator name="spin" type="torque" link="rod" axis="0 -1 0"/>)" + extra + R"(
    <simulation dt="1e-4" gravity=")" + gravity + R"(" tolerance="1e-12" max_iterations="500"/>
  </nscd>
</robot>)";
}

}  // namespace

// Driven along x at 0.1 m/s, gravity (2, -9.81, 0), a torque 1e-3 N m about the axis:
// x follows the command to round-off; y falls as -g t^2 / 2 (theta = 1/2 integrates a
// constant force exactly); the body spins at tau / Ixx t about x; the effort is the
// force that cancels gravity's x part, -m g_x. With the default constrain="all" the
// body keeps y and orientation and only x moves.
TEST(PrescribedAxis, FreeDofsFallAndSpinWhileTheAxisFollowsTheCommand) {
  const double gx = 2.0, gy = -9.81, tau = 1e-3;
  for (const char* constrain : {R"( constrain="axis")", ""}) {
    const bool axis_only = *constrain != '\0';
    Simulator sim(loadSceneFromString(rodScene("2 -9.81 0", constrain, ""), "rod.urdf"));
    ASSERT_EQ(sim.model().actuators[0].axis_only, axis_only);
    ASSERT_LT((sim.model().actuators[0].axis - Vec3::UnitX()).norm(), 1e-12);
    sim.setCommand(1, tau);
    const int steps = 2000;
    double worst_x = 0;
    for (int k = 1; k <= steps; ++k) {
      sim.setCommand(0, kSpeed * k * kDt);
      ASSERT_EQ(sim.step(), StepStatus::Ok);
      worst_x = std::max(worst_x, std::abs(sim.state().bodies[0].x.x() - kSpeed * k * kDt));
    }
    const double t = steps * kDt;
    const BodyState& b = sim.state().bodies[0];
    EXPECT_LT(worst_x, 1e-12) << constrain;
    EXPECT_NEAR(b.v.x(), kSpeed, 1e-12) << constrain;
    EXPECT_NEAR(sim.actuatorEffort(0), -kMass * gx, 1e-9) << constrain;
    if (axis_only) {
      EXPECT_NEAR(b.x.y(), 0.5 * gy * t * t, 1e-12);
      EXPECT_NEAR(b.v.y(), gy * t, 1e-12);
      EXPECT_NEAR(b.x.z(), 0.3, 1e-12);
      // Body frame: the link's -y is the body's axis along world x.
      const Vec3 w_world = b.q * b.w;
      EXPECT_NEAR(w_world.x(), tau / kIxx * t, 1e-9);
      EXPECT_NEAR(w_world.y(), 0.0, 1e-12);
      EXPECT_NEAR(w_world.z(), 0.0, 1e-12);
    } else {
      EXPECT_NEAR(b.x.y(), 0.0, 1e-12);
      EXPECT_NEAR(b.x.z(), 0.3, 1e-12);
      EXPECT_LT(b.w.norm(), 1e-12);
    }
  }
}

// The plunger bearing in small: a bore (hollow cylinder r 10 mm along x, 0.2 m long,
// on the ground) and the rod's two rings r 9 mm at x = +-50 mm; radial gap 1 mm, mu 0.2.
// Gravity -y. The rod, driven along x at 0.1 m/s, drops by the gap in
// sqrt(2 gap / g) = 14.3 ms, then rests on the bore's bottom, both rings loaded; the
// drive pushes against the sliding friction, effort mu m g. Free to turn about x,
// nothing turns it. After the transient a step allocates nothing.
TEST(PrescribedAxis, RodInABoreRestsOnItAndTheDrivePaysTheFriction) {
  const double mu = 0.2, g = 9.81, gap = 1e-3;
  const std::string bearing = R"(
    <contact name="front" mu="0.2">
      <shape link="rod" type="ring" radius="0.009"><origin xyz="0 -0.05 0" rpy="1.5707963267948966 0 0"/></shape>
      <shape link="world" type="cylinder" radius="0.01" length="0.2" hollow="true"><origin xyz="0 0 0.3" rpy="0 1.5707963267948966 0"/></shape>
    </contact>
    <contact name="rear" mu="0.2">
      <shape link="rod" type="ring" radius="0.009"><origin xyz="0 0.05 0" rpy="1.5707963267948966 0 0"/></shape>
      <shape link="world" type="cylinder" radius="0.01" length="0.2" hollow="true"><origin xyz="0 0 0.3" rpy="0 1.5707963267948966 0"/></shape>
    </contact>)";
  Simulator sim(loadSceneFromString(rodScene("0 -9.81 0", R"( constrain="axis")", bearing), "bore.urdf"));
  const int front = 0, rear = 1;
  ASSERT_EQ(sim.model().contacts[front].name, "front");
  const double t_drop = std::sqrt(2 * gap / g);
  int k = 0;
  double t_touch = -1;
  auto step = [&] {
    ++k;
    sim.setCommand(0, kSpeed * k * kDt);
    ASSERT_EQ(sim.step(), StepStatus::Ok);
  };
  while (k < 1000 && t_touch < 0) {
    step();
    if (sim.contactNormalForce(front) + sim.contactNormalForce(rear) > 0) t_touch = k * kDt;
  }
  // The impulse comes in the step that would carry the rod through the bore.
  EXPECT_NEAR(t_touch, t_drop, 1.5 * kDt);
  for (int i = 0; i < 500; ++i) step();
  const BodyState& b = sim.state().bodies[0];
  EXPECT_NEAR(b.x.x(), kSpeed * k * kDt, 1e-12);
  // On the bore's bottom: the velocity-level contact law stops the rod at the small positive
  // gap the landing step leaves (67 nm here), which nothing then closes.
  EXPECT_NEAR(b.x.y(), -gap, 1e-7);
  EXPECT_NEAR(b.x.z(), 0.3, 1e-8);
  EXPECT_LT(std::abs(b.v.y()), 1e-6);
  EXPECT_LT((b.q * b.w).norm(), 1e-6);  // nothing turns it about its free axis
  EXPECT_NEAR(sim.contactNormalForce(front) + sim.contactNormalForce(rear), kMass * g, 1e-6 * kMass * g);
  EXPECT_GT(sim.contactNormalForce(front), 0.1 * kMass * g);
  EXPECT_GT(sim.contactNormalForce(rear), 0.1 * kMass * g);
  EXPECT_NEAR(sim.actuatorEffort(0), mu * kMass * g, 1e-6 * kMass * g);
  const long before = nscd_test::allocationCount();
  for (int i = 0; i < 100; ++i) step();
  EXPECT_EQ(nscd_test::allocationCount(), before);
}
