// State holds everything that moves: a run saved with state() and continued
// with setState() (on the same or another simulator) is bit-identical to the
// original; reset() and setState() clear every output of the last step.
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

Simulator load(const std::string& scene) {
  return Simulator(loadScene(nscd_test::scenePath(scene)));
}

// Bodies and time, compared to the bit.
void expectSameMotion(const State& a, const State& b, const std::string& where) {
  ASSERT_EQ(a.bodies.size(), b.bodies.size());
  EXPECT_EQ(a.t, b.t) << where;
  for (size_t i = 0; i < a.bodies.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(a.bodies[i].x[k], b.bodies[i].x[k]) << where << " body " << i;
      EXPECT_EQ(a.bodies[i].v[k], b.bodies[i].v[k]) << where << " body " << i;
      EXPECT_EQ(a.bodies[i].w[k], b.bodies[i].w[k]) << where << " body " << i;
    }
    EXPECT_EQ(a.bodies[i].q.coeffs(), b.bodies[i].q.coeffs()) << where << " body " << i;
  }
}

// Steps `n` times following the probe schedule (when the scene has a probe).
void run(Simulator& sim, int n) {
  const int probe = sim.model().findActuator("probe");
  static const CommandSchedule schedule = parseCommandSchedule("probe=0:0,0.0007:0,0.0207:0.004");
  for (int i = 0; i < n; ++i) {
    if (probe >= 0) sim.setCommand(probe, schedule.value(sim.state().t + sim.model().settings.dt));
    sim.step();
  }
}

}  // namespace

// Clearance pendulum (warm starts, ring hints) and the C-60 during its trip
// (commands, prescribed probe, latch): save, run on, restore, run again.
TEST(SimulatorState, RestoredRunIsBitIdentical) {
  for (const std::string scene : {"urdf/clearance_pendulum.urdf", "urdf/c60.urdf"}) {
    Simulator sim = load(scene);
    run(sim, 300);
    const State saved = sim.state();
    run(sim, 400);
    const State reference = sim.state();
    const int iterations = sim.stats().iterations;

    sim.setState(saved);  // the same simulator
    run(sim, 400);
    expectSameMotion(sim.state(), reference, scene + ", same simulator");
    EXPECT_EQ(sim.stats().iterations, iterations) << scene;
    EXPECT_EQ(sim.state().warm_valid, reference.warm_valid) << scene;

    Simulator other = load(scene);  // a branch on another simulator
    other.setState(saved);
    run(other, 400);
    expectSameMotion(other.state(), reference, scene + ", other simulator");
  }
}

// The warm starts are part of the state: a restore without them is another run
// (so the test above could fail if State missed them).
TEST(SimulatorState, WarmStartsAreState) {
  Simulator sim = load("urdf/c60.urdf");
  run(sim, 300);
  State saved = sim.state();
  run(sim, 50);
  const State reference = sim.state();
  std::fill(saved.warm_valid.begin(), saved.warm_valid.end(), 0);
  std::fill(saved.warm_bilateral.begin(), saved.warm_bilateral.end(), 0.0);
  sim.setState(saved);
  run(sim, 50);
  bool differs = false;
  for (size_t i = 0; i < reference.bodies.size(); ++i)
    differs = differs || sim.state().bodies[i].x != reference.bodies[i].x;
  EXPECT_TRUE(differs) << "cold warm starts gave the same bits: the solver ignores them?";
}

// After reset() (and setState()) no output of the last step survives: forces of
// named contacts and clearance joints, contact reports, efforts, statistics.
TEST(SimulatorState, ResetClearsEveryOutput) {
  Simulator sim = load("urdf/c60.urdf");
  run(sim, 100);
  const int c7 = [&] {
    for (size_t i = 0; i < sim.model().contacts.size(); ++i)
      if (sim.model().contacts[i].name == "C7") return static_cast<int>(i);
    return -1;
  }();
  ASSERT_GE(c7, 0);
  ASSERT_GT(sim.contactNormalForce(c7), 1.0) << "C7 carries the contact pressure at rest";
  ASSERT_FALSE(sim.contactPoints().empty());
  ASSERT_GT(sim.stats().iterations, 0);
  const int probe = sim.model().findActuator("probe");
  ASSERT_GE(probe, 0);

  const State mid = sim.state();
  sim.reset();
  EXPECT_EQ(sim.state().t, 0.0);
  EXPECT_EQ(sim.contactNormalForce(c7), 0.0);
  EXPECT_EQ(sim.contactTangentialForce(c7), 0.0);
  for (size_t j = 0; j < sim.model().clearance_joints.size(); ++j)
    EXPECT_EQ(sim.clearanceNormalForce(static_cast<int>(j)), 0.0);
  EXPECT_TRUE(sim.contactPoints().empty());
  EXPECT_EQ(sim.actuatorEffort(probe), 0.0);
  EXPECT_EQ(sim.stats().iterations, 0);
  EXPECT_EQ(sim.stats().active_contacts, 0);

  run(sim, 100);
  ASSERT_GT(sim.contactNormalForce(c7), 1.0);
  sim.setState(mid);
  EXPECT_EQ(sim.contactNormalForce(c7), 0.0);
  EXPECT_TRUE(sim.contactPoints().empty());
}

// A state of another model, or with a NaN, is refused and leaves the run as it was.
TEST(SimulatorState, SetStateRefusesForeignOrNonFiniteStates) {
  Simulator pendulum = load("urdf/clearance_pendulum.urdf");
  Simulator c60 = load("urdf/c60.urdf");
  const State before = pendulum.state();
  EXPECT_THROW(pendulum.setState(c60.state()), std::invalid_argument);
  State bad = pendulum.state();
  bad.bodies[0].v.x() = NAN;
  EXPECT_THROW(pendulum.setState(bad), std::invalid_argument);
  bad = pendulum.state();
  bad.warm.pop_back();
  EXPECT_THROW(pendulum.setState(bad), std::invalid_argument);
  expectSameMotion(pendulum.state(), before, "after refused setState");
}
