// The projection's energy take-back (src/engine/step/energy_bookkeeping.cpp) on a
// scene with a known answer: a ball dropped plastically onto a plane and, in the
// same model, a slider on a frictionless horizontal prismatic joint that nothing
// touches. The ball's impact step drifts it into the plane (theta = 1/2: half the
// step at the old velocity) and the projection lifts it back, adding m g x drift of
// potential energy; that step dissipates far more (the ball's 0.5 J), so the step
// as a whole gains nothing and nothing may be taken from the slider. (The rule of
// one common factor on every velocity took the lift's energy from the slider and
// stopped it: 2.9 mJ against its 0.2 mJ.)
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
