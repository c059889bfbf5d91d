// One test per stage of the time step (src/engine/step/step_stages.hpp), each on a case
// with a known answer: forces and their derivatives, joint rows, the Delassus
// operator, the projection, the time integration, command schedules.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "step/step_stages.hpp"

using namespace nscd;

namespace {

// A scene of one free body `box` (mass 2 kg, inertia diag(0.01, 0.02, 0.03)) at
// (0, 0, 1) with the given <nscd> content and joint (floating by default).
Model boxScene(const std::string& nscd, const std::string& joint_type = "floating",
               const std::string& axis = "0 0 1") {
  const std::string urdf = R"(<?xml version="1.0"?>
<robot name="stage">
  <link name="world"/>
  <link name="box">
    <inertial><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
  </link>
  <joint name="j" type=")" + joint_type + R"(">
    <parent link="world"/><child link="box"/><origin xyz="0 0 1"/><axis xyz=")" + axis + R"("/>
    <limit lower="-10" upper="10" effort="1" velocity="1"/>
  </joint>
  <nscd>)" + nscd + R"(</nscd>
</robot>)";
  return loadSceneFromString(urdf, "stage.urdf");
}

struct Stages {
  Model m;
  StepWorkspace ws;
  StepOutputs out;
  State s;
  explicit Stages(Model model) : m(std::move(model)) {
    initStepWorkspace(m, ws);
    initStepOutputs(m, out);
    s = initialState(m, ws);
  }
};

}  // namespace

// Gravity m g; a linear spring to ground: tension k (L - L0) + c dL/dt along the
// line, and dF/dq = -k along it (the body's x row, symmetric part).
TEST(Stages, ForcesOfGravityAndALinearSpring) {
  Stages t(boxScene(R"(<spring name="s" type="linear" stiffness="100" rest_length="0.5" damping="3">
      <end link="box" xyz="0 0 0"/><end link="world" xyz="-1 0 1"/></spring>
      <simulation gravity="0 0 -9.81"/>)"));
  t.s.bodies[0].v = Vec3(0.2, 0, 0);  // away from the anchor: L grows at 0.2 m/s
  computeForces(t.m, t.s, t.ws, t.out, true);
  // L = 1, tension = 100 (1 - 0.5) + 3 * 0.2 = 50.6 N, pulling the box towards -x.
  EXPECT_NEAR(t.ws.F[0], -50.6, 1e-9);
  EXPECT_NEAR(t.ws.F[1], 0.0, 1e-12);
  EXPECT_NEAR(t.ws.F[2], -2 * 9.81, 1e-12);
  EXPECT_NEAR(springForceAt(t.m, t.s, 0), 50.6, 1e-9);
  EXPECT_NEAR(t.ws.K(0, 0), -100.0, 1e-4);  // along the spring: -k
  EXPECT_NEAR(t.ws.C(0, 0), -3.0, 1e-6);    // damping: -c
  // Across the spring the line turns: -tension / L = -50.6 (geometric stiffness).
  EXPECT_NEAR(t.ws.K(1, 1), -50.6, 1e-3);
}

// An undamped linear spring's K is computed in closed form (forces.cpp); it must be
// the symmetric part of dF/dq, here by central differences of F through the same
// perturbations (x += eps, q <- q exp(phi)), on a turned box with the spring's end
// off its centre (so the torque rows and the orientation columns matter), within
// the differences' own error.
TEST(Stages, UndampedSpringStiffnessMatchesDifferences) {
  Stages t(boxScene(R"(<spring name="s" type="linear" stiffness="100" rest_length="0.5">
      <end link="box" xyz="0.05 0.02 -0.03"/><end link="world" xyz="-1 0.3 1"/></spring>
      <simulation gravity="0 0 0"/>)"));
  t.s.bodies[0].q = expMap(Vec3(0.3, -0.5, 0.7));
  computeForces(t.m, t.s, t.ws, t.out, true);
  const Eigen::Matrix<double, 6, 6> K = t.ws.K.topLeftCorner<6, 6>();
  Eigen::Matrix<double, 6, 6> D;
  const double eps = 1e-6;
  for (int dof = 0; dof < 6; ++dof) {
    Eigen::Matrix<double, 6, 1> f[2];
    for (int side = 0; side < 2; ++side) {
      State p = t.s;
      const double e = side ? -eps : eps;
      if (dof < 3) {
        p.bodies[0].x[dof] += e;
      } else {
        Vec3 phi = Vec3::Zero();
        phi[dof - 3] = e;
        p.bodies[0].q = (p.bodies[0].q * expMap(phi)).normalized();
      }
      computeForces(t.m, p, t.ws, t.out, false);
      f[side] = t.ws.F.head<6>();
    }
    D.col(dof) = (f[0] - f[1]) / (2 * eps);
  }
  const Eigen::Matrix<double, 6, 6> Dsym = 0.5 * (D + D.transpose());
  EXPECT_GT(K.norm(), 10.0);  // the spring is stretched and turned: K is not trivial
  EXPECT_LT((K - Dsym).norm(), 1e-6 * K.norm()) << "K\n" << K << "\ndifferences\n" << Dsym;
}

// A PD actuator on a revolute joint: effort kp (cmd - angle) - kd rate about the
// axis, on the child, the opposite on the parent (ground here).
TEST(Stages, ForcesOfAPositionActuator) {
  Stages t(boxScene(R"(<actuator name="m" type="position" joint="j" kp="4" kd="0.5"/>
      <simulation gravity="0 0 0"/>)", "revolute"));
  t.s.commands[0] = 0.3;
  t.s.bodies[0].q = Quat(Eigen::AngleAxisd(0.1, Vec3::UnitZ()));
  t.s.bodies[0].w = Vec3(0, 0, 0.2);  // body frame = world z here
  computeForces(t.m, t.s, t.ws, t.out, false);
  const double effort = 4 * (0.3 - 0.1) - 0.5 * 0.2;
  EXPECT_NEAR(t.out.actuator_effort[0], effort, 1e-12);
  EXPECT_NEAR(t.ws.F[5], effort, 1e-12);  // torque about body z (= world z)
  EXPECT_NEAR(jointPosition(t.m, t.s, 0), 0.1, 1e-12);
  EXPECT_NEAR(jointVelocity(t.m, t.s, 0), 0.2, 1e-12);
}

// Revolute joint rows: a rotation about the joint axis through the anchor
// violates none (G v = 0); a translation along x violates the x point row only.
// At the assembled pose every error is 0.
TEST(Stages, RevoluteJointRows) {
  Stages t(boxScene("<simulation gravity=\"0 0 0\"/>", "revolute", "0 1 0"));
  appendBilateralRows(t.m, t.s, t.ws.rates, t.ws);
  ASSERT_EQ(t.ws.blocks.size(), 1u);
  ASSERT_EQ(t.ws.rows, 5);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(t.ws.blocks[0].error[k], 0.0, 1e-15);
  Eigen::VectorXd v = Eigen::VectorXd::Zero(6);
  v.tail<3>() = Vec3(0, 1.7, 0);  // spin about the joint axis (body frame = world)
  EXPECT_LT((t.ws.G.topRows(5) * v).norm(), 1e-15);
  v.setZero();
  v[0] = 0.4;
  const Eigen::VectorXd u = t.ws.G.topRows(5) * v;
  EXPECT_NEAR(u[0], 0.4, 1e-15);
  EXPECT_NEAR(u.tail<4>().norm(), 0.0, 1e-15);
  v.setZero();
  v[3] = 1.0;  // spin about x: tilts the axis
  EXPECT_GT((t.ws.G.topRows(5) * v).tail<2>().norm(), 0.5);
}

// The Delassus operator of one contact normal n at lever r from the centre of
// mass: W = 1/m + (r x n)^T J^-1 (r x n).
TEST(Stages, DelassusOfOneContactRow) {
  Stages t(boxScene("<simulation gravity=\"0 0 0\"/>"));
  ConstraintBlock blk;
  blk.kind = BlockKind::Frictionless;
  blk.size = 1;
  blk.body_a = 0;
  blk.body_b = kGround;
  const Vec3 r(0.1, -0.05, 0.2), n = Vec3(0.3, 0.4, 1.0).normalized();
  blk.contact.row_cp.point_a = t.s.bodies[0].x + r;
  blk.contact.row_cp.normal = n;
  t.ws.blocks.push_back(blk);
  writeJacobianRows(t.s, blk, t.ws.G);
  t.ws.rows = 1;
  assembleDelassus(t.ws.mass_inverse, true, t.ws, 0, 1);
  const Vec3 rn = r.cross(n);
  const double expected = 1.0 / 2.0 + rn.dot(Vec3(rn.x() / 0.01, rn.y() / 0.02, rn.z() / 0.03));
  EXPECT_NEAR(t.ws.W(0, 0), expected, 1e-12);
  // Y = M^-1 G^T: the velocity change per unit impulse.
  EXPECT_NEAR(t.ws.Y(0, 0), n.x() / 2.0, 1e-15);
}

// A sphere 1 mm into a plane is lifted out along the normal by exactly its
// penetration (one row, no rotation), to the projection tolerance.
TEST(Stages, ProjectionLiftsAPenetratingSphere) {
  Stages t(boxScene(R"(<contact name="c" mu="0.5" e="0">
      <shape link="box" type="sphere" radius="0.1"/>
      <shape link="world" type="plane"/></contact>
      <simulation gravity="0 0 -9.81" projection_tolerance="1e-12"/>)"));
  t.s.bodies[0].x = Vec3(0.2, 0.3, 0.099);
  double violation = 1;
  StepStats st;
  const int passes = projectPositions(t.m, t.s, t.ws, 50, 1e-12, violation, st);
  EXPECT_GE(passes, 1);
  EXPECT_LE(violation, 1e-12);
  EXPECT_NEAR(t.s.bodies[0].x.z(), 0.1, 1e-12);
  EXPECT_NEAR(t.s.bodies[0].x.x(), 0.2, 1e-15);
  EXPECT_NEAR(t.s.bodies[0].q.angularDistance(Quat::Identity()), 0.0, 1e-15);
  EXPECT_NEAR(measureViolation(t.m, t.s, t.ws), 0.0, 1e-12);
}

// Theta-scheme position update: x += h (theta v1 + (1 - theta) v0); the
// quaternion turns by h (theta w1 + (1 - theta) w0) about that (body) axis, unit.
TEST(Stages, TimeIntegrationOfTheThetaScheme) {
  State s;
  s.bodies.resize(1);
  s.bodies[0].q = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX()));
  Eigen::VectorXd v0(6), v1(6);
  v0 << 1, 2, 3, 0, 0, 2;
  v1 << 3, 2, 1, 0, 0, 4;
  const double h = 0.01, theta = 0.5;
  integratePositions(s, v0, v1, h, theta);
  EXPECT_NEAR((s.bodies[0].x - Vec3(0.02, 0.02, 0.02)).norm(), 0.0, 1e-15);
  const Quat expected = Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX())) *
                        Quat(Eigen::AngleAxisd(0.03, Vec3::UnitZ()));
  EXPECT_NEAR(s.bodies[0].q.angularDistance(expected), 0.0, 1e-14);
  EXPECT_NEAR(s.bodies[0].q.norm(), 1.0, 1e-15);
}

// The iteration matrix Ŵ is the inverse of A = M - h theta C - h^2 theta^2 K: with a
// PD actuator on a revolute joint (its torque reads the orientation and spin only:
// the translation DOFs are M's alone, inverted on their own) and with a damped
// linear spring (every DOF coupled).
TEST(Stages, IterationMatrixIsTheInverse) {
  const char* scenes[] = {
      R"(<actuator name="m" type="position" joint="j" kp="40" kd="5"/>)",
      R"(<spring name="s" type="linear" stiffness="3000" rest_length="0.5" damping="20">
           <end link="box" xyz="0.1 0.05 0"/><end link="world" xyz="0.3 -0.4 1.2"/></spring>)"};
  for (int k = 0; k < 2; ++k) {
    Stages t(boxScene(scenes[k], k == 0 ? "revolute" : "floating"));
    t.s.commands.assign(t.s.commands.size(), 0.3);
    t.s.bodies[0].q = Quat(Eigen::AngleAxisd(0.1, Vec3(0.2, 0.1, 1).normalized()));
    t.s.bodies[0].w = Vec3(0.1, -0.2, 0.3);
    const double h = 1e-2;
    computeForces(t.m, t.s, t.ws, t.out, true);
    stateVelocities(t.s, t.ws.vk);
    StepStats st;
    buildIterationMatrix(t.m, h, t.ws, st);
    ASSERT_FALSE(st.iteration_matrix_fallback);
    const double theta = t.m.settings.theta;
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    A.topLeftCorner<3, 3>() = 2 * Mat3::Identity();
    A.bottomRightCorner<3, 3>() = Vec3(0.01, 0.02, 0.03).asDiagonal();
    A -= h * theta * t.ws.C.topLeftCorner<6, 6>() + h * h * theta * theta * t.ws.K.topLeftCorner<6, 6>();
    const Eigen::Matrix<double, 6, 6> W = t.ws.iteration_inverse.topLeftCorner<6, 6>();
    EXPECT_LT((A * W - Eigen::Matrix<double, 6, 6>::Identity()).norm(), 1e-12) << "scene " << k << "\n" << A * W;
    if (k == 0) {  // translation: 1 / m, alone
      EXPECT_NEAR(W(0, 0), 0.5, 1e-15);
      EXPECT_EQ(W.row(0).tail<5>().norm(), 0.0);
    } else {
      EXPECT_NE(W(0, 1), 0.0);  // the spring couples x and y
    }
  }
}

// Free velocity of a body with no force but gravity: v_k + h g; a body spinning
// about a principal axis gets no gyroscopic impulse.
TEST(Stages, FreeVelocityUnderGravity) {
  Stages t(boxScene("<simulation gravity=\"0 0 -10\"/>"));
  t.s.bodies[0].w = Vec3(0, 0, 5);
  computeForces(t.m, t.s, t.ws, t.out, false);
  stateVelocities(t.s, t.ws.vk);
  StepStats st;
  buildIterationMatrix(t.m, 1e-3, t.ws, st);
  computeFreeVelocity(t.m, 1e-3, t.ws);
  EXPECT_NEAR(t.ws.vfree[2], -0.01, 1e-15);
  EXPECT_EQ(t.ws.vfree[5], 5.0);
  EXPECT_FALSE(st.iteration_matrix_fallback);
}

// Schedules: linear between points, held before the first and after the last;
// bound to actuators by name.
TEST(Stages, CommandSchedules) {
  const CommandSchedule s = parseCommandSchedule("m=0.1:1,0.3:2,0.3:5,0.5:5");
  EXPECT_EQ(s.actuator, "m");
  EXPECT_EQ(s.value(0.0), 1.0);
  EXPECT_NEAR(s.value(0.2), 1.5, 1e-15);
  EXPECT_EQ(s.value(0.3), 2.0);  // a step: the first value at its time
  EXPECT_EQ(s.value(0.4), 5.0);
  EXPECT_EQ(s.value(9.0), 5.0);
  const Model m = boxScene("<actuator name=\"m\" type=\"position\" joint=\"j\" kp=\"1\" kd=\"0\"/>",
                           "revolute");
  const auto bound = bindCommandSchedules({"m=0:0,1:1"}, m);
  ASSERT_EQ(bound.size(), 1u);
  EXPECT_EQ(bound[0].actuator, 0);
  EXPECT_THROW(bindCommandSchedules({"nosuch=0:0"}, m), std::invalid_argument);
  EXPECT_THROW(bindCommandSchedules({"m=0:0", "m=1:1"}, m), std::invalid_argument);
  EXPECT_THROW(parseCommandSchedule("m=1:0,0:1"), std::invalid_argument);
  // The scene's own schedule is bound when no text names the actuator, and a text
  // replaces it.
  const Model ms = boxScene("<actuator name=\"m\" type=\"position\" joint=\"j\" kp=\"1\" schedule=\"0:3,1:4\"/>",
                            "revolute");
  const auto own = bindCommandSchedules({}, ms);
  ASSERT_EQ(own.size(), 1u);
  EXPECT_EQ(own[0].actuator, 0);
  EXPECT_EQ(own[0].schedule.actuator, "m");
  EXPECT_NEAR(own[0].schedule.value(0.5), 3.5, 1e-15);
  const auto over = bindCommandSchedules({"m=0:7"}, ms);
  ASSERT_EQ(over.size(), 1u);
  EXPECT_EQ(over[0].schedule.value(0.5), 7.0);
}

// Values near the largest double (accepted: the format sets no range): the
// interpolation stays between its points instead of overflowing to -inf, which
// setCommand would drop. Found by fuzz/command_schedule_fuzzer.cpp.
TEST(Stages, CommandScheduleOfHugeValuesStaysBetweenItsPoints) {
  const CommandSchedule s = parseCommandSchedule("m=0.0007:0,0.0007:1e308,7:4");
  for (const double t : {0.001, 2.187981, 6.9}) {
    const double v = s.value(t);
    EXPECT_TRUE(std::isfinite(v)) << t;
    EXPECT_GE(v, 4.0) << t;
    EXPECT_LE(v, 1e308) << t;
  }
  const CommandSchedule wide = parseCommandSchedule("m=0:-1.7e308,1:1.7e308");
  EXPECT_NEAR(wide.value(0.5), 0.0, 1e293);
  EXPECT_EQ(wide.value(1.0), 1.7e308);
}

// Times of a few subnormal steps: (b - a) (t - t0) underflows and rounds, so the
// usual form gave -0.667 at the schedule's own last time, past its value -0.5.
// Found by fuzz/command_schedule_fuzzer.cpp (fuzz/regressions/command_schedule/
// subnormal_times).
TEST(Stages, CommandScheduleOfSubnormalTimesStaysBetweenItsPoints) {
  const CommandSchedule s = parseCommandSchedule("m=0:0,14.9e-324:-0.5");
  const double t1 = s.points.back().first;
  ASSERT_GT(t1, 0.0);
  for (int ulps = 0; ulps <= 4; ++ulps) {
    const double t = ulps * 4.9406564584124654e-324;
    const double v = s.value(t);
    EXPECT_GE(v, -0.5) << ulps << " ulps";
    EXPECT_LE(v, 0.0) << ulps << " ulps";
  }
  EXPECT_EQ(s.value(t1), -0.5);
}
