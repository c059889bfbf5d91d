// Springs whose scalar reaches the bodies as body-fixed loads (<spring><force>,
// <couple>) and torsion springs on the relative angle of two links (<angle>), each
// against a closed form: a follower force that keeps a spinning body on a circle,
// two bodies oscillating about their relative angle, the loads' work against the
// kinetic energy, the loads' linearisation, and no allocation in a step.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "step/step_stages.hpp"
#include "test_support.hpp"

using namespace nscd;

namespace {

// Two free bodies: `a` (mass 2 kg, inertia diag(0.01, 0.02, 0.03)) at (0, 0, 1) and
// `b` (mass 1 kg, diag(0.02, 0.03, 0.05)) at (1, 0, 1) yawed by yaw_b; `a_turned`, a
// link fixed to a, yawed by 0.7 rad (its frame is not the body's); no gravity; the
// given <nscd> content.
Model twoBodies(const std::string& nscd, double yaw_b = 0, const std::string& dt = "1e-4") {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="loads">
  <link name="world"/>
  <link name="a"><inertial><mass value="2"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial></link>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.05"/></inertial></link>
  <link name="a_turned"/>
  <joint name="place_a" type="floating"><parent link="world"/><child link="a"/><origin xyz="0 0 1"/></joint>
  <joint name="place_b" type="floating"><parent link="world"/><child link="b"/>
    <origin xyz="1 0 1" rpy="0 0 )" + std::to_string(yaw_b) + R"("/></joint>
  <joint name="turn" type="fixed"><parent link="a"/><child link="a_turned"/><origin xyz="0.2 0 0" rpy="0 0 0.7"/></joint>
  <nscd>)" + nscd + R"(
    <simulation dt=")" + dt + R"(" gravity="0 0 0" projection="false"/>
  </nscd>
</robot>)";
  return loadSceneFromString(urdf, "loads.urdf");
}

double yawOf(const Quat& q) {
  const Mat3 R = q.toRotationMatrix();
  return std::atan2(R(1, 0), R(0, 0));
}

}  // namespace

// Body a spins at w about its principal z axis; a linear spring (k 50 N/m, rest
// 0.5 m) from the world point c = (0, 0, 1) to its centre of mass reaches it as a
// body-fixed force, twice the tension, along body -x at the centre of mass: a force
// of constant magnitude turning with the body. Started at c + (rho, 0, 0) with the
// speed rho w along +y, the body stays on the circle of radius rho about c where
// 2 k (rho - L0) = m rho w^2 (rho = 50/92 m): uniform circular motion, the spring's
// length constant. (The spring's own line force, k (rho - L0), would not hold it
// there, nor would a force fixed in the world.)
TEST(SpringLoads, BodyFixedForceKeepsASpinningBodyOnItsCircle) {
  const double k = 50, L0 = 0.5, m = 2, w = 2;
  const double rho = 2 * k * L0 / (2 * k - m * w * w);
  Model model = twoBodies(R"(
    <spring name="pull" type="linear" stiffness="50" rest_length="0.5">
      <end link="world" xyz="0 0 1"/><end link="a"/>
      <force link="a" direction="-1 0 0" scale="2"/>
    </spring>)");
  model.bodies[0].initial_pose.p = Vec3(rho, 0, 1);
  model.bodies[0].initial_velocity = Vec3(0, rho * w, 0);
  model.bodies[0].initial_angular_velocity = Vec3(0, 0, w);
  Simulator sim(std::move(model));
  const double h = sim.model().settings.dt;
  const int n = static_cast<int>(std::round(M_PI / w / h));  // half a turn
  double worst = 0;
  for (int i = 1; i <= n; ++i) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const double t = i * h;
    const Vec3 expect(rho * std::cos(w * t), rho * std::sin(w * t), 1);
    worst = std::max(worst, (sim.bodyPose(0).p - expect).norm());
  }
  // A wrong direction or scale is off by cm; without the skew part of the loads'
  // linearisation (iteration_matrix.cpp) by 2.4 mm.
  EXPECT_LT(worst, 1e-6);
  printf("worst %g\n", worst);
  EXPECT_NEAR(sim.springForce(0), k * (rho - L0), 1e-5);  // the scalar: the tension
  // Nothing turns it but its spin (the force acts at the centre of mass).
  EXPECT_NEAR(std::remainder(yawOf(sim.bodyPose(0).q) - w * n * h, 2 * M_PI), 0.0, 1e-9);
}

// Bodies a and b, free, turned about z by a torsion spring on their relative angle:
// that of b's frame to the frame of a_turned, a link of a yawed by 0.7 rad. b starts
// yawed by 3.7 rad, so the angle starts at 3.0 rad; rest 3.1 rad: the angle
// theta = 3.1 - 0.1 cos(W t), W^2 = k (1/Ia + 1/Ib), passes pi without a jump; a
// turns against b in the ratio of their inertias (the angular momentum stays 0).
TEST(SpringLoads, TorsionOnARelativeAngleOscillatesAboutItsRest) {
  const double k = 0.8, Ia = 0.03, Ib = 0.05, rest = 3.1;
  Simulator sim(twoBodies(R"(
    <spring name="twist" type="torsion" stiffness="0.8" rest_angle="3.1">
      <angle link_a="a_turned" link_b="b" axis="0 0 1"/>
    </spring>)", 3.7));
  const double W = std::sqrt(k * (1 / Ia + 1 / Ib));
  const double h = sim.model().settings.dt;
  EXPECT_NEAR(sim.model().springs[0].relative_initial, 3.0, 1e-12);
  EXPECT_NEAR(sim.springForce(0), -k * (3.0 - rest), 1e-12);
  const int n = static_cast<int>(std::round(2 * M_PI / W / h));  // one period
  double worst = 0, worst_momentum = 0, largest_angle = 0;
  for (int i = 1; i <= n; ++i) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const double theta = rest - 0.1 * std::cos(W * i * h);
    const double expect_a = -(theta - 3.0) * Ib / (Ia + Ib);
    worst = std::max(worst, std::abs(yawOf(sim.bodyPose(0).q) - expect_a));
    // The angle the spring reads: rest - torque / k.
    const double read = rest - sim.springForce(0) / k;
    worst = std::max(worst, std::abs(read - theta));
    largest_angle = std::max(largest_angle, read);
    worst_momentum = std::max(worst_momentum, std::abs(Ia * sim.angularVelocityWorld(0).z() +
                                                       Ib * sim.angularVelocityWorld(1).z()));
  }
  EXPECT_GT(largest_angle, M_PI + 0.05);  // read past pi, continuously
  EXPECT_LT(worst, 2e-7);                 // rad
  EXPECT_LT(worst_momentum, 1e-12);
}

// The same spring written as its two couples (+1 on b, -1 on a about the axis) moves
// the bodies as the spring's own moment pair does, to round-off.
TEST(SpringLoads, CouplesOfTheMomentPairMoveAsThePair) {
  const std::string angle = R"(<angle link_a="a" link_b="b" axis="0 0 1"/>)";
  Simulator pair(twoBodies(R"(<spring name="s" type="torsion" stiffness="0.8" rest_angle="0.4">)" + angle +
                           "</spring>", 0.1));
  Simulator loads(twoBodies(R"(<spring name="s" type="torsion" stiffness="0.8" rest_angle="0.4">)" + angle +
                            R"(<couple link="b" axis="0 0 1" scale="1"/><couple link="a" axis="0 0 -2" scale="1"/>
                            </spring>)", 0.1));
  for (int i = 0; i < 2000; ++i) {
    ASSERT_EQ(pair.step(), StepStatus::Ok);
    ASSERT_EQ(loads.step(), StepStatus::Ok);
  }
  for (int b = 0; b < 2; ++b)
    EXPECT_LT((pair.bodyPose(b).q.coeffs() - loads.bodyPose(b).q.coeffs()).norm(), 1e-12) << b;
  EXPECT_GT(std::abs(yawOf(pair.bodyPose(1).q) - 0.1), 0.05);  // it did turn
  // A spring applied as loads has no potential; the pair has 1/2 k stretch^2.
  EXPECT_EQ(loads.energy().springs, 0.0);
  const double stretch = yawOf(pair.bodyPose(1).q) - yawOf(pair.bodyPose(0).q) - 0.4;
  EXPECT_NEAR(pair.energy().springs, 0.5 * 0.8 * stretch * stretch, 1e-12);
}

// Not conservative: the plugin-style couples +1 on b and -1.25 on a give the pair
// angular momentum and change its energy. Over 0.3 s the kinetic energy's change
// equals the loads' work (trapezoidal sum of their power over the steps) to 1e-5 of
// it, and the energy bookkeeping's count (power at each step's end x h, O(h)) to 5e-4
// here; each step's input work (inputWorkOfStep) is that count when positive.
TEST(SpringLoads, LoadsWorkIsTheKineticEnergysChange) {
  Model model = twoBodies(R"(
    <spring name="s" type="torsion" stiffness="0.8" rest_angle="0.4">
      <angle link_a="a" link_b="b" axis="0 0 1"/>
      <couple link="b" axis="0 0 1" scale="1"/>
      <couple link="a" axis="0 0 1" scale="-1.25"/>
    </spring>)");
  model.bodies[0].initial_angular_velocity = Vec3(0, 0, 0.5);  // not a pure oscillation
  Simulator sim(std::move(model));
  StepWorkspace ws;
  StepOutputs out;
  initStepWorkspace(sim.model(), ws);
  initStepOutputs(sim.model(), out);
  const double h = sim.model().settings.dt;
  const double e0 = sim.energy().total();
  double power = springLoadPowerAt(sim.model(), sim.state(), 0);
  double work = 0, counted = 0, largest = 0;
  int positive = 0;
  for (int i = 0; i < 3000; ++i) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const double next = springLoadPowerAt(sim.model(), sim.state(), 0);
    work += 0.5 * (power + next) * h;
    power = next;
    counted += next * h;
    largest = std::max(largest, std::abs(sim.energy().total() - e0));
    EXPECT_DOUBLE_EQ(inputWorkOfStep(sim.model(), h, ws, out, sim.state()), std::max(0.0, next * h));
    positive += next > 0;
  }
  const double momentum = 0.03 * sim.angularVelocityWorld(0).z() + 0.05 * sim.angularVelocityWorld(1).z();
  EXPECT_GT(positive, 100);
  EXPECT_GT(largest, 1e-3);  // the energy does change (J)
  EXPECT_NEAR(sim.energy().total() - e0, work, 1e-5 * largest);
  EXPECT_NEAR(sim.energy().total() - e0, counted, 5e-4 * largest);
  EXPECT_GT(std::abs(momentum - 0.03 * 0.5), 1e-3);  // and so does the angular momentum
}

// The loads are linearised into the iteration matrix by the differences of
// forces.cpp: for one body under a torsion law on its angle to the world (k, rest)
// applied as a force s tau along body-fixed d at body point p, dF/dq in closed form
// (body-frame turns phi, yaw change dtheta = phi_z at a yaw-only pose):
//   world force  s tau R d:     d/dphi = -s k (R d) e_z^T - s tau R [d]x
//   body torque  s tau p x d:   d/dphi = -s k (p x d) e_z^T
// and K is its symmetric part.
TEST(SpringLoads, LoadsAreLinearisedIntoTheIterationMatrix) {
  const double k = 0.7, rest = 0.9, s = 3.0, yaw = 0.3;
  Model model = twoBodies(R"(
    <spring name="s" type="torsion" stiffness="0.7" rest_angle="0.9">
      <angle link_a="world" link_b="b" axis="0 0 1"/>
      <force link="b" xyz="0.1 -0.2 0.05" direction="0.6 0.8 0" scale="3"/>
    </spring>)", yaw);
  StepWorkspace ws;
  StepOutputs out;
  initStepWorkspace(model, ws);
  initStepOutputs(model, out);
  State st = initialState(model, ws);
  computeForces(model, st, ws, out, true);
  const Vec3 p(0.1, -0.2, 0.05), d(0.6, 0.8, 0);
  const Mat3 R = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  const double tau = -k * (yaw - rest);
  Mat3 dx;
  dx << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
  Eigen::Matrix<double, 6, 6> K = Eigen::Matrix<double, 6, 6>::Zero();
  K.block<3, 3>(0, 3) = -s * k * (R * d) * Vec3::UnitZ().transpose() - s * tau * R * dx;
  K.block<3, 3>(3, 3) = -s * k * p.cross(d) * Vec3::UnitZ().transpose();
  const Eigen::Matrix<double, 6, 6> sym = 0.5 * (K + K.transpose());
  const Eigen::Matrix<double, 6, 6> got = ws.K.block<6, 6>(6, 6);
  EXPECT_LT((got - sym).norm(), 1e-6 * sym.norm()) << "got\n" << got << "\nexpected\n" << sym;
  // And the force itself.
  EXPECT_LT((ws.F.segment<3>(6) - s * tau * R * d).norm(), 1e-12);
  EXPECT_LT((ws.F.segment<3>(9) - s * tau * p.cross(d)).norm(), 1e-12);
}

// A step of a scene with loaded springs (torsion on a relative angle, linear) does not
// allocate.
TEST(SpringLoads, AStepAllocatesNothing) {
  Simulator sim(twoBodies(R"(
    <spring name="t" type="torsion" stiffness="0.8" rest_angle="0.4">
      <angle link_a="a" link_b="b" axis="0 0 1"/>
      <couple link="b" axis="0 0 1" scale="1"/><force link="a" xyz="0 0.1 0" direction="1 0 0" scale="-2"/>
    </spring>
    <spring name="l" type="linear" stiffness="30" rest_length="0.8">
      <end link="a"/><end link="b" xyz="0.1 0 0"/>
      <force link="b" xyz="0.1 0 0" direction="-1 0 0" scale="1"/>
    </spring>)"));
  for (int i = 0; i < 10; ++i) ASSERT_EQ(sim.step(), StepStatus::Ok);
  const long before = nscd_test::allocationCount();
  for (int i = 0; i < 100; ++i) sim.step();
  EXPECT_EQ(nscd_test::allocationCount(), before);
}
