// Joints driven through many turns: the joint angle is followed continuously
// across +-pi (State::joint_position), so a prescribed crank follows its command
// and a PD crank its ramp with the PD's tracking error, turn after turn.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "physics_scenes.hpp"

using namespace nscd;
using nscd_test::crankScene;

namespace {

// A bar (0.1 kg, 0.2 m, COM 0.1 m from the pivot) on a vertical hinge, no gravity,
// with `nscd` (an actuator on the hinge, an initial position) in its <nscd>.
Simulator crank(const std::string& nscd) {
  const std::string urdf = crankScene(nscd + R"(<simulation dt="1e-4" gravity="0 0 0"/>)");
  return Simulator(loadSceneFromString(urdf, "crank.urdf"));
}

constexpr double kOmega = 20 * M_PI;  // 10 turns a second

}  // namespace

// Prescribed at 10 turns/s for 1 s: the joint follows the command to 1e-9 rad
// all the way (it spun away by 126 rad once the command passed pi when the
// angle was taken in (-pi, pi]).
TEST(JointDrives, PrescribedCrankFollowsTenTurns) {
  Simulator sim = crank(R"(<actuator name="drive" type="prescribed" joint="hinge"/>)");
  const double h = sim.model().settings.dt;
  double worst = 0;
  for (int k = 1; k <= 10000; ++k) {
    sim.setCommand(0, kOmega * k * h);
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
    worst = std::max(worst, std::abs(sim.jointPosition(0) - kOmega * k * h));
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_NEAR(sim.jointPosition(0), 20 * M_PI, 1e-9);
  // The bar itself is where the angle says.
  const Pose p = sim.linkPose(1);
  EXPECT_NEAR(std::remainder(2 * std::atan2(p.q.z(), p.q.w()) - 20 * M_PI, 2 * M_PI), 0.0, 1e-9);
}

// A PD crank on a ramp of 10 turns/s settles to the PD's steady tracking error
// kd omega / kp (J theta'' = kp (theta_c - theta) - kd theta' with theta' = omega).
TEST(JointDrives, PdCrankTracksTheRampWithItsSteadyError) {
  // J = 1.33e-3 kg m^2 about the hinge: omega_n = 38.8 rad/s, damping ratio 0.97.
  const double kp = 2.0, kd = 0.1;
  Simulator sim = crank(R"(<actuator name="drive" type="position" joint="hinge" kp="2" kd="0.1"/>)");
  const double h = sim.model().settings.dt;
  for (int k = 1; k <= 10000; ++k) {
    sim.setCommand(0, kOmega * k * h);
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
    if (k * h > 0.5) {  // the transient decays as exp(-37 t): settled
      const double error = kOmega * k * h - sim.jointPosition(0);
      ASSERT_NEAR(error, kd * kOmega / kp, 1e-3 * kd * kOmega / kp) << "t = " << k * h;
    }
  }
  EXPECT_GT(sim.jointPosition(0), 18 * M_PI) << "the crank turned with its command";
}

// A joint placed several turns round (<initial position="10">) starts its
// continuous angle there: a PD drive holding the initial command does not
// unwind the turns.
TEST(JointDrives, InitialPositionKeepsItsTurns) {
  Simulator sim = crank(R"(<initial joint="hinge" position="10"/>
    <actuator name="drive" type="position" joint="hinge" kp="2" kd="0.1"/>)");
  EXPECT_NEAR(sim.jointPosition(0), 10.0, 1e-12);
  EXPECT_NEAR(sim.command(0), 10.0, 1e-12);
  for (int k = 0; k < 2000; ++k) sim.step();
  EXPECT_NEAR(sim.jointPosition(0), 10.0, 1e-9);
}

// A torque actuator whose schedule is in the scene: 0.01 N m about the hinge for
// 0.1 s, then none. J = Izz + m d^2 = 1.33e-3 kg m^2: omega = tau t / J and
// theta = tau t^2 / (2 J) while it acts, then the bar turns on at constant omega.
// Bound and applied as nscd_run does (the command at the end of each step).
TEST(JointDrives, TorqueActuatorFollowsTheScenesSchedule) {
  Simulator sim = crank(R"(<actuator name="spin" type="torque" link="bar" axis="0 0 2"
      schedule="0:0.01,0.1:0.01,0.1:0"/>)");
  const auto schedules = bindCommandSchedules({}, sim.model());
  ASSERT_EQ(schedules.size(), 1u);
  const double h = sim.model().settings.dt, J = 3.3e-4 + 0.1 * 0.1 * 0.1, tau = 0.01;
  for (int k = 1; k <= 2000; ++k) {
    applySchedules(schedules, k * h, sim);
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
    if (k == 1000) {
      EXPECT_NEAR(sim.actuatorEffort(0), tau, 1e-15);
      EXPECT_NEAR(sim.jointVelocity(0), tau * 0.1 / J, 1e-6 * tau * 0.1 / J);
      EXPECT_NEAR(sim.jointPosition(0), tau * 0.01 / (2 * J), 1e-3 * tau * 0.01 / (2 * J));
    }
  }
  EXPECT_EQ(sim.actuatorEffort(0), 0.0);
  EXPECT_NEAR(sim.jointVelocity(0), tau * 0.1 / J, 1e-6 * tau * 0.1 / J);
  EXPECT_NEAR(sim.jointPosition(0), tau * 0.01 / (2 * J) + tau * 0.1 / J * 0.1, 1e-3 * tau * 0.01 / J);
}
