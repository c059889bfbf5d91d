// Physics of the engine core against analytic answers.
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

Simulator makeSim(const std::string& xml, const std::vector<SettingOverride>& o = {}) {
  return Simulator(loadSceneFromString(xml, "test.urdf", o));
}

// Complete elliptic integral of the first kind, by the arithmetic-geometric mean.
double ellipticK(double k) {
  double a = 1, b = std::sqrt(1 - k * k);
  for (int i = 0; i < 40; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return M_PI / (2 * a);
}

}  // namespace

// A sphere dropped from 1 m with e = 0.9 bounces to e^(2k) h0 (within 0.5%),
// penetrating less than 1e-6 m.
TEST(Physics, BouncingBallApexHeights) {
  const double h0 = 1.0, e = 0.9, r = 0.05;
  Simulator sim = makeSim(ballScene(h0, e, 0.0, 1e-4));
  std::vector<double> apex;
  double prev_vz = 0, max_pen = 0;
  while (sim.state().t < 3.2 && apex.size() < 3) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const BodyState& b = sim.state().bodies[0];
    max_pen = std::max(max_pen, sim.stats().max_penetration);
    max_pen = std::max(max_pen, r - b.x.z());
    if (prev_vz > 0 && b.v.z() <= 0) {
      // Apex between the two last steps: z + v^2 / 2g from the last state.
      apex.push_back(b.x.z() - r + b.v.z() * b.v.z() / (2 * 9.81));
    }
    prev_vz = b.v.z();
  }
  ASSERT_EQ(apex.size(), 3u);
  std::printf("[ figures  ] apex heights %.6f %.6f %.6f m (expected %.6f %.6f %.6f), max penetration %.3e m\n",
              apex[0], apex[1], apex[2], h0 * e * e, h0 * std::pow(e, 4), h0 * std::pow(e, 6), max_pen);
  for (int k = 0; k < 3; ++k) {
    const double expected = h0 * std::pow(e, 2 * (k + 1));
    EXPECT_NEAR(apex[k], expected, 0.005 * expected) << "bounce " << k + 1;
  }
  EXPECT_LT(max_pen, 1e-6);
}

// A sphere held between two walls with no play, moving into the lower one at
// 1 m/s, e = 0.5, no gravity: both contacts are active, the upper one separating.
// Newton's law on every active contact (u_N+ >= -e u_N-) bounces the sphere at
// e times its speed, v_k = (-e)^k v_0; with the law on approaching contacts only,
// the upper contact (u_N+ >= 0) would contradict the lower (u_N+ >= e v): a
// problem with no solution, left unconverged every step.
TEST(Physics, BallBetweenTwoWallsBouncesAtE) {
  const double r = 0.05, e = 0.5, v0 = -1.0;
  for (double mu : {0.0, 0.4}) {
    std::string xml = ballScene(0.0, e, mu, 1e-4);
    const std::string upper = R"(<nscd><contact name="ceiling" mu=")" + num(mu) + R"(" e=")" + num(e) +
                              R"("><shape link="ball" type="sphere" radius=")" + num(r) +
                              R"("/><shape link="world" type="plane"><origin xyz="0 0 )" + num(2 * r) +
                              R"(" rpy="3.141592653589793 0 0"/></shape></contact></nscd>
  <nscd><initial link="ball" vz=")" + num(v0) + R"("/></nscd>
  <nscd><simulation)";
    xml.replace(xml.find("<nscd><simulation"), 17, upper);
    xml.replace(xml.find("gravity=\"0 0 -9.81\""), 20, "gravity=\"0 0 0\"");
    Simulator sim = makeSim(xml);
    double expected = v0;
    for (int k = 1; k <= 6; ++k) {
      ASSERT_EQ(sim.step(), StepStatus::Ok);
      expected *= -e;
      EXPECT_TRUE(sim.stats().converged) << "mu " << mu << " step " << k;
      EXPECT_EQ(sim.stats().active_contacts, 2) << "mu " << mu << " step " << k;
      EXPECT_NEAR(sim.state().bodies[0].v.z(), expected, 1e-9) << "mu " << mu << " step " << k;
    }
  }
}

// A box on a 15 degree slope with mu = 0.3 sticks: it moves less than 1e-6 m in 1 s.
TEST(Physics, BlockSticksBelowFrictionAngle) {
  const double alpha = 15 * M_PI / 180;
  Simulator sim = makeSim(slopeScene(alpha, 0.3, 1e-4));
  const Vec3 x0 = sim.state().bodies[0].x;
  for (int k = 0; k < 10000; ++k) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  const double moved = (sim.state().bodies[0].x - x0).norm();
  EXPECT_LT(moved, 1e-6);
  // Normal force = m g cos(alpha) (within 0.5%).
  EXPECT_NEAR(sim.contactNormalForce(0), 9.81 * std::cos(alpha), 0.005 * 9.81);
}

// On a 25 degree slope it slides with a = g (sin(alpha) - mu cos(alpha)) (within 1%).
TEST(Physics, BlockSlidesAboveFrictionAngle) {
  const double alpha = 25 * M_PI / 180, mu = 0.3, g = 9.81;
  Simulator sim = makeSim(slopeScene(alpha, mu, 1e-4));
  const Vec3 down(0, -std::cos(alpha), -std::sin(alpha));
  for (int k = 0; k < 2000; ++k) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  const double v1 = sim.state().bodies[0].v.dot(down), t1 = sim.state().t;
  for (int k = 0; k < 6000; ++k) ASSERT_NE(sim.step(), StepStatus::NonFinite);
  const double v2 = sim.state().bodies[0].v.dot(down), t2 = sim.state().t;
  const double a = (v2 - v1) / (t2 - t1);
  const double expected = g * (std::sin(alpha) - mu * std::cos(alpha));
  EXPECT_NEAR(a, expected, 0.01 * expected);
  // It stays on the plane: no lift-off, no penetration beyond the projection tolerance.
  EXPECT_LT(std::abs(sim.contactGap(0)), 1e-8);
}

// A disc whose rim is a `ring` rolls down a 20 degree `face` (mu 0.5, enough to
// roll without slipping): a = g sin(alpha) / (1 + I/(m r^2)) = 2/3 g sin(alpha)
// along the slope (within 1%), omega = v / r (within 1%), normal force m g
// cos(alpha) (within 1%). Once the rim's lowest point has passed the face's
// lower edge the face gives no point any more: the disc falls freely (a = -g
// within 1%).
TEST(Physics, RingRollsDownFaceAndFallsOffItsEdge) {
  const double r = 0.01, alpha = 20 * M_PI / 180, len = 0.2, g = 9.81, m = 0.1;
  Simulator sim = makeSim(ringOnFaceScene(r, alpha, len, 0.05, 0.5, 1e-4));
  const Vec3 down(-std::cos(alpha), -std::sin(alpha), 0);
  for (int k = 0; k < 500; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  const double v1 = sim.state().bodies[0].v.dot(down), t1 = sim.state().t;
  for (int k = 0; k < 2000; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  const double v2 = sim.state().bodies[0].v.dot(down), t2 = sim.state().t;
  const double a = (v2 - v1) / (t2 - t1), expected = 2.0 / 3.0 * g * std::sin(alpha);
  std::printf("[ figures  ] ring on face: a = %.5f m/s^2 (expected %.5f), omega r / v = %.5f\n", a, expected,
              sim.angularVelocityWorld(0).z() * r / v2);
  EXPECT_NEAR(a, expected, 0.01 * expected);
  EXPECT_NEAR(sim.angularVelocityWorld(0).z() * r, v2, 0.01 * v2);  // rolling: anticlockwise going left
  EXPECT_NEAR(sim.contactNormalForce(0), m * g * std::cos(alpha), 0.01 * m * g);
  EXPECT_LT(std::abs(sim.contactGap(0)), 1e-8);
  // Roll on until the lowest rim point is 2 mm past the lower edge (s = -len/2).
  const Vec3 along(std::cos(alpha), std::sin(alpha), 0);
  auto slopeCoord = [&] { return sim.state().bodies[0].x.dot(along); };
  while (slopeCoord() > -0.5 * len - 0.002) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    ASSERT_LT(sim.state().t, 2.0);
  }
  const double vy1 = sim.state().bodies[0].v.y(), ty1 = sim.state().t;
  for (int k = 0; k < 200; ++k) ASSERT_EQ(sim.step(), StepStatus::Ok);
  const double ay = (sim.state().bodies[0].v.y() - vy1) / (sim.state().t - ty1);
  EXPECT_NEAR(ay, -g, 0.01 * g);
  EXPECT_EQ(sim.contactNormalForce(0), 0.0);
}

// An ideal revolute pendulum released from 30 degrees has the exact large-amplitude
// period T = 4 sqrt(I_O / (m g l)) K(sin(theta0/2)) (within 0.5%).
TEST(Physics, PendulumLargeAmplitudePeriod) {
  const double l = 1.0, m = 1.0, I = 1e-3, th0 = 30 * M_PI / 180, g = 9.81;
  Simulator sim = makeSim(pendulumScene(l, m, I, th0, 1e-4));
  const double T = 4 * std::sqrt((I + m * l * l) / (m * g * l)) * ellipticK(std::sin(th0 / 2));
  // Times at which the angular velocity about y changes sign from - to + (turning points).
  std::vector<double> turns;
  double prev = 0;
  while (sim.state().t < 2.6 * T) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const double wy = sim.angularVelocityWorld(0).y();
    if (prev < 0 && wy >= 0) turns.push_back(sim.state().t - sim.model().settings.dt * wy / (wy - prev));
    prev = wy;
  }
  ASSERT_GE(turns.size(), 2u);
  const double period = turns[1] - turns[0];
  EXPECT_NEAR(period, T, 0.005 * T);
  // The hinge keeps the pivot fixed.
  EXPECT_LT(sim.constraintViolation(), 1e-9);
}

// Frictionless, e = 1, undamped: no energy gain over 1e5 steps at theta = 0.5.
TEST(Physics, NoEnergyGainFrictionlessElastic) {
  Simulator sim = makeSim(ballScene(0.2, 1.0, 0.0, 1e-4));
  const double E0 = sim.energy().total();
  double Emax = E0;
  for (int k = 0; k < 100000; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    if (k % 100 == 0) Emax = std::max(Emax, sim.energy().total());
  }
  const double E1 = sim.energy().total();
  std::printf("[ figures  ] e=1 ball, 1e5 steps: E0 %.9f J, max %.9f J (%+.2e rel), final %.9f J (%+.2e rel)\n",
              E0, Emax, Emax / E0 - 1, E1, E1 / E0 - 1);
  EXPECT_LE(Emax, E0 * (1 + 1e-6));
  EXPECT_LE(E1, E0 * (1 + 1e-6));
  // and it does not dissipate much either (e = 1): within 2% after ~25 bounces.
  EXPECT_GE(E1, 0.98 * E0);
}

// A free body with inertia diag(1, 2, 3) g m^2, spun about its major axis with a
// small wobble, no gravity: its kinetic energy may not grow (an explicit
// gyroscopic torque gains h^2/2 |w x Jw|^2_{J^-1} per step, ~0.2% over these 1e4
// steps), and its angular momentum
// in the world frame is conserved to within the scheme's first-order error.
TEST(Physics, TumblingBodyGainsNoEnergy) {
  const std::string xml = R"(<robot name="top">
  <link name="world"/>
  <link name="top"><inertial><mass value="1"/><inertia ixx="1e-3" iyy="2e-3" izz="3e-3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="free" type="floating"><parent link="world"/><child link="top"/></joint>
  <nscd><initial link="top" vx="0" vy="0" vz="0" wx="0.5" wy="0.3" wz="10"/></nscd>
  <nscd><simulation dt="1e-3" gravity="0 0 0" projection="false"/></nscd>
</robot>)";
  Simulator sim = makeSim(xml);
  const Mat3 J = Vec3(1e-3, 2e-3, 3e-3).asDiagonal();
  const auto momentum = [&] {
    const BodyState& b = sim.state().bodies[0];
    return Vec3(b.q * (J * b.w));
  };
  const double K0 = sim.energy().kinetic;
  const Vec3 L0 = momentum();
  double Kmax = K0, Lerr = 0;
  for (int k = 0; k < 10000; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    Kmax = std::max(Kmax, sim.energy().kinetic);
    Lerr = std::max(Lerr, (momentum() - L0).norm() / L0.norm());
  }
  const double K1 = sim.energy().kinetic;
  std::printf("[ figures  ] tumbling body, 1e4 steps of 1 ms: K max %+.2e rel, final %+.2e rel, "
              "|L - L0|/|L0| max %.2e\n", Kmax / K0 - 1, K1 / K0 - 1, Lerr);
  EXPECT_LE(Kmax, K0 * (1 + 1e-12));
  EXPECT_GE(K1, 0.99 * K0);  // backward Euler dissipates, but little
  EXPECT_LT(Lerr, 1e-2);
}

// A closed four-bar written with a loop joint assembles and keeps its constraint
// violation below 1e-9 m over 1 s.
TEST(Physics, FourBarLoopStaysClosed) {
  Simulator sim = makeSim(fourBarScene(M_PI / 2, 5.0, 1e-4, 2e-3));  // 2 mm mismatch at start
  EXPECT_LT(sim.constraintViolation(), 1e-9);
  const Quat crank0 = sim.state().bodies[0].q;
  double worst = 0;
  for (int k = 0; k < 10000; ++k) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    if (k % 10 == 0) worst = std::max(worst, sim.constraintViolation());
  }
  std::printf("[ figures  ] four-bar: max loop violation over 1 s %.3e m\n", worst);
  EXPECT_LT(worst, 1e-9);
  // It moved: the crank turned by more than 0.1 rad.
  EXPECT_GT(crank0.angularDistance(sim.state().bodies[0].q), 0.1);
}

// A spring-mass oscillator matches its analytic period 2 pi sqrt(m/k) (0.1%) and amplitude.
TEST(Physics, SpringMassPeriod) {
  const double m = 1.0, k = 100.0, A = 0.1;
  Simulator sim = makeSim(springMassScene(m, k, A, 1e-4));
  const double T = 2 * M_PI * std::sqrt(m / k);
  std::vector<double> turns;
  double prev = 0, xmin = 1e9;
  while (sim.state().t < 3.2 * T) {
    ASSERT_EQ(sim.step(), StepStatus::Ok);
    const double vx = sim.state().bodies[0].v.x();
    xmin = std::min(xmin, sim.state().bodies[0].x.x());
    if (prev < 0 && vx >= 0) turns.push_back(sim.state().t - sim.model().settings.dt * vx / (vx - prev));
    prev = vx;
  }
  ASSERT_GE(turns.size(), 3u);
  EXPECT_NEAR((turns[2] - turns[0]) / 2, T, 1e-3 * T);
  EXPECT_NEAR(xmin, 0.5 - 2 * A, 1e-3 * A);
  EXPECT_NEAR(sim.springForce(0), k * (sim.state().bodies[0].x.x() - 0.4), 1e-6);
}
