// The 3D revolute joint with radial and axial clearance, against known answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"
#include "physics_scenes.hpp"

using namespace nscd;
using namespace nscd_test;

namespace {

Simulator makeSim(const std::string& xml) {
  return Simulator(loadSceneFromString(xml, "test.urdf"));
}

// Normal force of each radial ring (features 0 and 1) of clearance joint 0.
void ringForces(const Simulator& sim, double& f0, double& f1) {
  f0 = f1 = 0;
  for (const ContactReport& c : sim.contactPoints()) {
    if (!c.clearance) continue;
    if (c.feature == 0) f0 += c.fn;
    if (c.feature == 1) f1 += c.fn;
  }
}

// Angle of the arm about z from its centre-of-mass direction (hinge at the origin).
double armAngle(const Simulator& sim) {
  const Vec3 x = sim.state().bodies[0].x;
  return std::atan2(x.x(), -x.y());
}

}  // namespace

// A 0.2 kg sleeve on a fixed pin (r 5 mm, c_r 0.05 mm) drops by exactly c_r,
// ends with ecc = 1 and carries J.fn = m g, shared equally by its two rings.
TEST(ClearanceJoint, SleeveRestsOnPin) {
  const double cr = 0.05e-3, m = 0.2, g = 9.81;
  Simulator sim = makeSim(sleeveScene(cr, 0.0, 0.2, -g, 1e-4));
  const double z0 = sim.state().bodies[0].x.z();
  for (int k = 0; k < 2000; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  const double drop = z0 - sim.state().bodies[0].x.z();
  EXPECT_NEAR(drop, cr, 0.002 * cr);
  EXPECT_NEAR(sim.clearanceEccentricity(0), 1.0, 0.01);
  EXPECT_NEAR(sim.clearanceNormalForce(0), m * g, 0.005 * m * g);
  double f0, f1;
  ringForces(sim, f0, f1);
  EXPECT_NEAR(f0, 0.5 * m * g, 0.01 * m * g);
  EXPECT_NEAR(f1, 0.5 * m * g, 0.01 * m * g);
  // Polarisation: the pin (journal) bears on the top of the bore, so every loaded ring
  // contact's normal (from the journal axis to the ring point) points up (+z).
  int loaded = 0;
  for (const ContactReport& c : sim.contactPoints()) {
    if (!c.clearance || c.fn <= 0) continue;
    ++loaded;
    EXPECT_GT(c.normal.z(), 0.999) << c.normal.transpose();
  }
  EXPECT_EQ(loaded, 2);
  EXPECT_LT(sim.stats().max_penetration, 0.01 * cr);
}

// Centre of mass 5 mm off-centre along the axis: the rings share the weight by the
// lever rule (rings at -10 mm and +10 mm: 25% / 75%).
TEST(ClearanceJoint, LeverRuleWithOffCentreMass) {
  const double cr = 0.05e-3, m = 0.2, g = 9.81;
  Simulator sim = makeSim(sleeveScene(cr, 5e-3, 0.2, -g, 1e-4));
  for (int k = 0; k < 3000; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  double f0, f1;
  ringForces(sim, f0, f1);
  EXPECT_NEAR(f0, 0.25 * m * g, 0.01 * m * g);
  EXPECT_NEAR(f1, 0.75 * m * g, 0.01 * m * g);
  EXPECT_NEAR(f0 + f1, m * g, 0.005 * m * g);
}

// Centre of mass outside the bearing (15 mm off-centre): one ring lifts, the sleeve
// tilts on the other and on an axial bump... the journal tilts inside the bearing.
TEST(ClearanceJoint, OverhangingMassTiltsTheSleeve) {
  const double cr = 0.05e-3;
  Simulator sim = makeSim(sleeveScene(cr, 15e-3, 0.2, -9.81, 1e-4));
  for (int k = 0; k < 3000; ++k) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  const Vec3 axis = sim.state().bodies[0].q * Vec3::UnitX();
  // Tilt of the sleeve axis: at most ~2 c_r / L, and clearly non-zero.
  const double tilt = std::asin(std::min(1.0, std::hypot(axis.y(), axis.z())));
  EXPECT_GT(tilt, 0.5 * cr / 20e-3);
  EXPECT_LT(tilt, 2.5 * cr / 20e-3);
}

// A force along the axis is carried by the three bumps of one face equally.
TEST(ClearanceJoint, AxialForceSharedByThreeBumps) {
  const std::string push =
      R"(  <nscd><actuator name="push" type="force" link="sleeve" xyz="0 0 0" direction="1 0 0" command="1.5"/></nscd>
)";
  Simulator sim = makeSim(sleeveScene(0.05e-3, 0.0, 0.2, 0.0, 1e-4, push));
  for (int k = 0; k < 3000; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  std::vector<double> bump;
  for (const ContactReport& c : sim.contactPoints())
    if (c.clearance && c.feature >= 2 && c.fn > 1e-9) bump.push_back(c.fn);
  ASSERT_EQ(bump.size(), 3u);
  for (double f : bump) EXPECT_NEAR(f, 0.5, 0.01 * 0.5);
  EXPECT_NEAR(sim.clearanceNormalForce(0), 1.5, 0.005 * 1.5);
}

// 1 µm clearance, mu = 0: follows the ideal revolute pendulum within 2e-3 rad over 1 s.
TEST(ClearanceJoint, SmallClearanceApproachesIdealJoint) {
  const double rj = 2e-3, l = 0.1, th0 = 30 * M_PI / 180, h = 1e-5;
  Simulator ideal = makeSim(clearancePendulumScene(0, 0, rj, l, th0, h));
  Simulator loose = makeSim(clearancePendulumScene(1e-6, 0.0, rj, l, th0, h));
  double worst = 0;
  for (int k = 0; k < 100000; ++k) {
    ASSERT_EQ(ideal.step(), StepStatus::Ok);
    ASSERT_NE(loose.step(), StepStatus::NonFinite);
    if (k % 100 == 0) worst = std::max(worst, std::abs(armAngle(ideal) - armAngle(loose)));
  }
  std::printf("[ figures  ] 1 um clearance vs ideal: max angle difference %.3e rad over 1 s\n", worst);
  EXPECT_LT(worst, 2e-3);
}

// 50 µm clearance, mu = 0.1, from 30 degrees: the swing decays per half swing as a
// friction-circle estimate predicts: d(theta) = 2 mu' (r_j / l) (theta0/sin theta0) N/(m g)
// with mu' = mu / sqrt(1 + mu^2) and the mean normal force N = m g (3 sin(t0)/t0 - 2 cos t0).
// With projection the penetration stays below 1% of the clearance.
TEST(ClearanceJoint, FrictionDecaysTheSwing) {
  const double cr = 50e-6, mu = 0.1, rj = 4.5e-3, l = 0.05, th0 = 30 * M_PI / 180;
  Simulator sim = makeSim(clearancePendulumScene(cr, mu, rj, l, th0, 1e-5));
  std::vector<double> peaks;
  double prev_w = 0, max_pen = 0;
  while (sim.state().t < 1.2 && peaks.size() < 5) {
    ASSERT_NE(sim.step(), StepStatus::NonFinite);
    max_pen = std::max(max_pen, sim.stats().max_penetration);
    const double w = sim.angularVelocityWorld(0).z();
    if ((prev_w > 0 && w <= 0) || (prev_w < 0 && w >= 0)) peaks.push_back(std::abs(armAngle(sim)));
    prev_w = w;
  }
  ASSERT_GE(peaks.size(), 4u);
  const double mu_c = mu / std::sqrt(1 + mu * mu);
  const double nbar = 3 * std::sin(th0) / th0 - 2 * std::cos(th0);
  const double estimate = 2 * mu_c * (rj / l) * (th0 / std::sin(th0)) * nbar;
  const double decay = (th0 - peaks[3]) / 4;  // mean over the first four half swings
  std::printf("[ figures  ] decay per half swing %.4f deg (friction-circle estimate %.4f deg), "
              "max penetration %.3e m = %.3f%% of c_r\n",
              decay * 180 / M_PI, estimate * 180 / M_PI, max_pen, 100 * max_pen / cr);
  EXPECT_NEAR(decay, estimate, 0.12 * estimate);
  EXPECT_LT(max_pen, 0.01 * cr);
}

// Without projection the velocity-level scheme lets constraints drift (the paper's
// warning): the penetration is much larger than with projection.
TEST(ClearanceJoint, DriftWithoutProjection) {
  const double cr = 50e-6, rj = 4.5e-3, l = 0.05, th0 = 30 * M_PI / 180;
  Simulator on = makeSim(clearancePendulumScene(cr, 0.1, rj, l, th0, 1e-4, true));
  Simulator off = makeSim(clearancePendulumScene(cr, 0.1, rj, l, th0, 1e-4, false));
  double pen_on = 0, pen_off = 0;
  for (int k = 0; k < 5000; ++k) {
    ASSERT_NE(on.step(), StepStatus::NonFinite);
    ASSERT_NE(off.step(), StepStatus::NonFinite);
    pen_on = std::max(pen_on, on.stats().max_penetration);
    pen_off = std::max(pen_off, off.stats().max_penetration);
  }
  std::printf("[ figures  ] h=1e-4, 0.5 s: max penetration with projection %.3e m, without %.3e m (c_r %.1e)\n",
              pen_on, pen_off, cr);
  EXPECT_LT(pen_on, 0.01 * cr);
  EXPECT_GT(pen_off, 10 * pen_on);
}

// Plain Moreau-Jean, a pin sliding around its hole (planar pendulum, c_r 0.1 mm,
// l 50 mm, h = 2.5e-4 s): with the contact rows built at q_k the hole-centre
// eccentricity grew by O(h^2) every step (4.3 c_r in a second: the lever arm's
// rotation and the normal's turn within the step); built at the predicted
// configuration (the default, as Siconos does) it stays where the first impact
// left it. Siconos 4.4 on the same model keeps 1.366 c_r; ours 1.303 (the first
// impact's steps, where the normal turns by > 0.1 rad, are built at q_k).
TEST(ClearanceJoint, PredictedRowsKeepTheSlidingPinOnItsCircle) {
  const double cr = 1e-4, rj = 5e-3, l = 0.05, h = 2.5e-4;
  const std::string xml = clearancePendulumScene(cr, 0.1, rj, l, 0.5, h, false, "xy");
  const auto eccentricity = [&](const Simulator& sim) {
    const BodyState& b = sim.state().bodies[0];
    return (b.x - b.q * Vec3(0, -l, 0)).norm() / cr;  // hole centre at the link origin
  };
  double grow[2];
  for (int p = 0; p < 2; ++p) {
    Simulator sim(loadSceneFromString(xml, "test.urdf", {{"contact_prediction", p ? "1" : "0", "test"}}));
    double e02 = 0;
    for (int k = 1; k <= 4000; ++k) {
      ASSERT_NE(sim.step(), StepStatus::NonFinite);
      if (k == 800) e02 = eccentricity(sim);
    }
    grow[p] = eccentricity(sim) - e02;
    std::printf("[ figures  ] contact_prediction %d: eccentricity %.4f c_r at 0.2 s, %.4f c_r at 1 s\n",
                p, e02, eccentricity(sim));
  }
  EXPECT_GT(grow[0], 1.0);          // the drift the prediction removes
  EXPECT_LT(std::abs(grow[1]), 1e-3);
}

// Planar mode: the single circle-in-circle contact and 3 DOF per body give the same
// in-plane motion as the 3D model.
TEST(ClearanceJoint, PlanarMatchesThreeD) {
  const double cr = 50e-6, rj = 4.5e-3, l = 0.05, th0 = 30 * M_PI / 180, h = 1e-5;
  Simulator s3 = makeSim(clearancePendulumScene(cr, 0.1, rj, l, th0, h, true, "false"));
  Simulator s2 = makeSim(clearancePendulumScene(cr, 0.1, rj, l, th0, h, true, "xy"));
  double worst = 0;
  for (int k = 0; k < 30000; ++k) {
    ASSERT_NE(s3.step(), StepStatus::NonFinite);
    ASSERT_NE(s2.step(), StepStatus::NonFinite);
    if (k % 100 == 0) worst = std::max(worst, std::abs(armAngle(s3) - armAngle(s2)));
  }
  std::printf("[ figures  ] planar vs 3D: max angle difference %.3e rad over 0.3 s\n", worst);
  EXPECT_LT(worst, 1e-3);
  EXPECT_NEAR(s2.state().bodies[0].x.z(), 0.0, 1e-12);
}
