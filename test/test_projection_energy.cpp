// The projection's energy take-back (src/engine/step/energy_bookkeeping.cpp) on
// scenes with a known answer.
//
// A ball dropped plastically onto a plane and, in the same model, a slider on a
// frictionless horizontal prismatic joint that nothing touches. The ball's impact
// step drifts it into the plane (theta = 1/2: half the step at the old velocity)
// and the projection lifts it back, adding m g x drift of potential energy; that
// step dissipates far more (the ball's 0.5 J), so the step as a whole gains
// nothing and nothing may be taken from the slider. (The rule of one common factor
// on every velocity took the lift's energy from the slider and stopped it: 2.9 mJ
// against its 0.2 mJ.)
//
// A ball falling from rest onto a plane, and another resting on it elsewhere, 1 um
// deep. In the first step the falling ball's contact is not yet a candidate (the
// search reaches 2 h |v_k| beyond the gap: 0 from rest), so it falls 0.49 mm, 0.39
// mm through the plane, and the projection lifts it (and the resting ball by its
// 1 um) with its velocity still into the plane: that step gains 3.8 mJ, taken
// back. Nothing acts on the resting ball but its weight and the plane: it stays at
// rest. (Taking the energy along the whole correction gave it 1.4e-4 m/s upwards,
// its own 1 um lift times the 138 /s that the falling ball's share called for.)
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

using namespace nscd;

namespace {

const char* kScene = R"(<?xml version="1.0"?>
<robot name="drop_and_slide">
  <link name="world"/>
  <link name="ball">
    <inertial><mass value="1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial>
  </link>
  <joint name="free" type="floating">
    <parent link="world"/><child link="ball"/><origin xyz="0 0 0.1002"/>
  </joint>
  <link name="slider">
    <inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
  </link>
  <joint name="rail" type="prismatic">
    <parent link="world"/><child link="slider"/><origin xyz="5 0 1"/><axis xyz="1 0 0"/>
    <limit lower="-10" upper="10" effort="1" velocity="1"/>
  </joint>
  <nscd>
    <contact name="floor" mu="0" e="0">
      <shape link="ball" type="sphere" radius="0.1"/>
      <shape link="world" type="plane"/>
    </contact>
    <simulation gravity="0 0 -9.81" dt="1e-3"/>
  </nscd>
</robot>)";

const char* kFallAndRest = R"(<?xml version="1.0"?>
<robot name="fall_and_rest">
  <link name="world"/>
  <link name="falling">
    <inertial><mass value="1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial>
  </link>
  <joint name="free_falling" type="floating">
    <parent link="world"/><child link="falling"/><origin xyz="0 0 0.1001"/>
  </joint>
  <link name="resting">
    <inertial><mass value="1"/>
      <inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial>
  </link>
  <joint name="free_resting" type="floating">
    <parent link="world"/><child link="resting"/><origin xyz="1 0 0.1"/>
  </joint>
  <nscd>
    <contact name="floor_falling" mu="0" e="0">
      <shape link="falling" type="sphere" radius="0.1"/>
      <shape link="world" type="plane"/>
    </contact>
    <contact name="floor_resting" mu="0" e="0">
      <shape link="resting" type="sphere" radius="0.1"/>
      <shape link="world" type="plane"/>
    </contact>
    <simulation gravity="0 0 -9.81" dt="1e-2"/>
  </nscd>
</robot>)";

}  // namespace

TEST(ProjectionEnergy, ALiftAfterAPlasticImpactStopsNothingElse) {
  Simulator sim(loadSceneFromString(kScene, "drop_and_slide.urdf"));
  const int ball = sim.model().findBody("ball");
  const int slider = sim.model().findBody("slider");
  ASSERT_GE(ball, 0);
  ASSERT_GE(slider, 0);
  State s = sim.state();
  s.bodies[ball].v = Vec3(0, 0, -1);      // 0.2 mm above the plane, falling at 1 m/s
  s.bodies[slider].v = Vec3(0.02, 0, 0);  // 0.2 mJ along its rail
  sim.setState(s);
  double energy = sim.energy().total();
  double lifted = 0;
  for (int k = 0; k < 20; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    lifted = std::max(lifted, sim.stats().projection_passes > 0 ? 1.0 : 0.0);
    // Nothing acts on the slider along its rail: its velocity stays 0.02 m/s
    // (to the bilateral rows' round-off).
    EXPECT_NEAR(sim.state().bodies[slider].v.x(), 0.02, 1e-12) << "step " << k;
    // A passive system: no step gains energy.
    const double e = sim.energy().total();
    EXPECT_LE(e, energy + 1e-12) << "step " << k;
    energy = e;
  }
  EXPECT_EQ(lifted, 1.0) << "the impact should drift the ball into the plane (the case under test)";
  // The ball ends at rest on the plane, lifted out of it.
  EXPECT_NEAR(sim.state().bodies[ball].x.z(), 0.1, 1e-6);
  EXPECT_NEAR(sim.state().bodies[ball].v.norm(), 0.0, 1e-9);
}

TEST(ProjectionEnergy, TheTakeBackSetsNoRestingBodyMoving) {
  Simulator sim(loadSceneFromString(kFallAndRest, "fall_and_rest.urdf"));
  const int falling = sim.model().findBody("falling");
  const int resting = sim.model().findBody("resting");
  ASSERT_GE(falling, 0);
  ASSERT_GE(resting, 0);
  State s = sim.state();
  s.bodies[resting].x.z() = 0.1 - 1e-6;  // 1 um into the plane (the assembly had lifted it)
  sim.setState(s);
  double energy = sim.energy().total();
  for (int k = 0; k < 20; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    if (k == 0) {
      EXPECT_GT(sim.stats().projection_passes, 0);
      EXPECT_GT(sim.stats().projection_energy_removed, 1e-3)
          << "the first step should fall through the plane and gain energy (the case under test)";
    }
    // The resting ball: its weight and the plane's reaction, nothing else (to the
    // solver's and the projection's tolerances).
    EXPECT_NEAR(sim.state().bodies[resting].v.norm(), 0.0, 1e-8) << "step " << k;
    EXPECT_NEAR(sim.state().bodies[resting].w.norm(), 0.0, 1e-8) << "step " << k;
    EXPECT_NEAR(sim.state().bodies[resting].x.z(), 0.1, 1e-8) << "step " << k;
    // A passive system: no step gains energy.
    const double e = sim.energy().total();
    EXPECT_LE(e, energy + 1e-12) << "step " << k;
    energy = e;
  }
  // The falling ball ends at rest on the plane.
  EXPECT_NEAR(sim.state().bodies[falling].x.z(), 0.1, 1e-6);
  EXPECT_NEAR(sim.state().bodies[falling].v.norm(), 0.0, 1e-9);
}
