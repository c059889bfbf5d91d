// Stage 1: forces. Gravity, springs (their own line force or moment pair, or the
// body-fixed loads the scene applies their scalar as), dampers and actuators, with
// the derivatives the Moreau-Jean iteration matrix needs for the stiff elements
// (springs and PD actuators), by finite differences per element (undamped linear
// springs without loads: in closed form). (Gyroscopic torques: free_velocity.cpp.)
#include <algorithm>
#include <array>
#include <cmath>

#include "joints/joint_rows.hpp"

namespace nscd {
namespace {


Vec3 pointWorld(const BodyState& b, const Vec3& local) { return b.q * local + b.x; }
Vec3 pointVelocity(const BodyState& b, const Vec3& local) {
  return b.v + b.q * (b.w.cross(local));
}

// Adds a world force applied at a world point to a body's generalized force.
void addForceAt(Vec6& g, const BodyState& b, const Vec3& f, const Vec3& p) {
  g.head<3>() += f;
  g.tail<3>() += b.q.conjugate() * ((p - b.x).cross(f));
}
void addTorque(Vec6& g, const BodyState& b, const Vec3& tau_world) {
  g.tail<3>() += b.q.conjugate() * tau_world;
}

// jointRate(j, a, b), given axis = a.q * j.axis_a: a revolute joint's rate
// (revoluteRate) from that axis instead of rotating it again; the same expressions
// on the same values, so the same bits.
double rateAbout(const Joint& j, const BodyState& a, const BodyState& b, const Vec3& axis) {
  if (j.type == JointType::Prismatic) return jointRate(j, a, b);
  return (b.q * b.w - a.q * a.w).dot(axis);
}

// A force element between two bodies: a spring or a position actuator.
struct Element {
  bool is_spring;
  int index;
  int body_a, body_b;
  int joint;  // torsion spring or PD actuator: its joint; else -1
};

// The joint whose coordinate a torsion spring reads: its joint, or the stand-in of
// its relative angle.
const Joint& angleJoint(const Model& m, const Spring& sp) {
  return sp.joint >= 0 ? m.joints[sp.joint] : sp.relative;
}

// The reference its continuous angle is read near: the joint's tracked angle, or
// the relative angle's initial value.
double angleReference(const Spring& sp, const State& s) {
  if (sp.type != SpringType::Torsion) return 0.0;
  return sp.joint >= 0 ? s.joint_position[sp.joint] : sp.relative_initial;
}

// A spring's scalar reaching its bodies as the scene's body-fixed loads: a force
// `scale` x scalar along a body-fixed direction at a body-fixed point, or a couple
// `scale` x scalar about a body-fixed axis (generalized forces: world force, body
// torque).
void addSpringLoads(const Spring& sp, const BodyState& a, const BodyState& b, double scalar,
                    Vec6& fa, Vec6& fb) {
  for (const SpringLoad& load : sp.loads) {
    Vec6& g = load.on_b ? fb : fa;
    const Vec3 v = (load.scale * scalar) * load.direction;  // body frame
    if (load.couple) {
      g.tail<3>() += v;
      continue;
    }
    g.head<3>() += (load.on_b ? b : a).q * v;
    g.tail<3>() += load.point.cross(v);
  }
}

// Generalized forces of an element on its two bodies. `report` gets the spring
// force (tension / torque on b) or the actuator effort. commands: unused for
// springs; angle_ref: the joint's continuous angle (torsion springs, PD actuators).
void elementForce(const Model& m, const Element& el, const BodyState& a, const BodyState& b,
                  const std::vector<double>& commands, double angle_ref, Vec6& fa, Vec6& fb,
                  double& report) {
  fa.setZero();
  fb.setZero();
  if (el.is_spring) {
    const Spring& sp = m.springs[el.index];
    if (sp.type == SpringType::Linear) {
      const Vec3 pa = pointWorld(a, sp.end_a), pb = pointWorld(b, sp.end_b);
      Vec3 d = pb - pa;
      const double L = d.norm();
      if (L < 1e-15) {  // direction undefined: no line force, no rate
        report = sp.loads.empty() ? 0.0 : sp.stiffness * (L - sp.rest);
        addSpringLoads(sp, a, b, report, fa, fb);
        return;
      }
      const Vec3 u = d / L;
      const double rate = (pointVelocity(b, sp.end_b) - pointVelocity(a, sp.end_a)).dot(u);
      const double f = sp.stiffness * (L - sp.rest) + sp.damping * rate;  // tension
      report = f;
      if (!sp.loads.empty()) {
        addSpringLoads(sp, a, b, f, fa, fb);
        return;
      }
      addForceAt(fa, a, f * u, pa);
      addForceAt(fb, b, -f * u, pb);
    } else {
      const Joint& j = angleJoint(m, sp);
      const double ang = jointCoordinateNear(j, a, b, angle_ref);
      const Vec3 axis = a.q * j.axis_a;
      const double rate = rateAbout(j, a, b, axis);
      const double tau = -sp.stiffness * (ang - sp.rest) - sp.damping * rate;  // on b
      report = tau;
      if (!sp.loads.empty()) {
        addSpringLoads(sp, a, b, tau, fa, fb);
        return;
      }
      addTorque(fb, b, tau * axis);
      addTorque(fa, a, -tau * axis);
    }
    return;
  }
  const Actuator& ac = m.actuators[el.index];
  const Joint& j = m.joints[ac.joint];
  const double pos = jointCoordinateNear(j, a, b, angle_ref);
  const Vec3 axis = a.q * j.axis_a;
  const double vel = rateAbout(j, a, b, axis);
  double effort = ac.kp * (commands[el.index] - pos) - ac.kd * vel;
  if (ac.max_effort > 0) effort = std::max(-ac.max_effort, std::min(ac.max_effort, effort));
  if (j.type == JointType::Prismatic) {
    const Vec3 pb = pointWorld(b, j.anchor_b);
    addForceAt(fb, b, effort * axis, pb);
    addForceAt(fa, a, -effort * axis, pb);
  } else {
    addTorque(fb, b, effort * axis);
    addTorque(fa, a, -effort * axis);
  }
  report = effort;
}

// K of an undamped linear spring, dF/dq through the exponential map (what the
// central differences below estimate): its force F = f u on A (f = k (L - L0))
// changes by S dd, S = k u uᵀ + f/L (I - u uᵀ), when the ends' separation d
// changes by dd = [-I, Ra [sa]x] (x_a, phi_a) + [I, -Rb [sb]x] (x_b, phi_b); the
// torques ±s x (Rᵀ F) also turn with their body. False (nothing added) when L = 0.
bool addLinearSpringStiffness(const Spring& sp, const BodyState& a, const BodyState& b,
                              int body_a, int body_b, Eigen::MatrixXd& K) {
  const Mat3 Ra = a.q.toRotationMatrix(), Rb = b.q.toRotationMatrix();
  const Vec3 d = (Rb * sp.end_b + b.x) - (Ra * sp.end_a + a.x);
  const double L = d.norm();
  if (L < 1e-15) return false;
  const Vec3 u = d / L;
  const double f = sp.stiffness * (L - sp.rest);
  const Mat3 uu = u * u.transpose();
  const Mat3 S = sp.stiffness * uu + (f / L) * (Mat3::Identity() - uu);
  const Vec3 F = f * u;
  Eigen::Matrix<double, 3, 6> dd[2];
  dd[0] << -Mat3::Identity(), Ra * skew(sp.end_a);
  dd[1] << Mat3::Identity(), -Rb * skew(sp.end_b);
  const int body[2] = {body_a, body_b};
  const Mat3 Rt[2] = {Ra.transpose(), Rb.transpose()};
  const Vec3 arm[2] = {sp.end_a, sp.end_b};
  const double sign[2] = {1.0, -1.0};  // F on A, -F on B
  for (int r = 0; r < 2; ++r) {
    if (body[r] == kGround) continue;
    for (int c = 0; c < 2; ++c) {
      if (body[c] == kGround) continue;
      const Eigen::Matrix<double, 3, 6> dF = S * dd[c];
      Eigen::Matrix<double, 6, 6> blk;
      blk.topRows<3>() = sign[r] * dF;
      blk.bottomRows<3>() = sign[r] * (skew(arm[r]) * (Rt[r] * dF));
      if (r == c) blk.bottomRightCorner<3, 3>() += sign[r] * (skew(arm[r]) * skew(Rt[r] * F));
      K.block<6, 6>(6 * body[r], 6 * body[c]) += blk;
    }
  }
  return true;
}

constexpr double kTurnStep = 1e-7;  // the differences' rotation step (rad)

// expMap(phi) of the six turns phi = +-kTurnStep about the body axes, made once
// with expMap itself: the same quaternions, without a sin and cos per perturbation.
const Quat& axisTurn(int axis, bool negative) {
  static const std::array<Quat, 6> turns = [] {
    std::array<Quat, 6> t;
    for (int k = 0; k < 6; ++k) {
      Vec3 phi = Vec3::Zero();
      phi[k % 3] = k < 3 ? kTurnStep : -kTurnStep;
      t[k] = expMap(phi);
    }
    return t;
  }();
  return turns[axis + (negative ? 3 : 0)];
}

// One perturbation of the differences: velocities and positions by eps; an
// orientation always by the turn of kTurnStep about the body axis, eps giving its sign.
void perturb(BodyState& b, int dof, double eps, bool position) {
  if (!position) {
    if (dof < 3) b.v[dof] += eps; else b.w[dof - 3] += eps;
  } else if (dof < 3) {
    b.x[dof] += eps;
  } else {
    b.q = (b.q * axisTurn(dof - 3, eps < 0)).normalized();
  }
}

}  // namespace

Vec3 bodyPointWorld(const State& s, int body, const Vec3& local) {
  return pointWorld(bodyOrGround(s, body), local);
}

double springForceAt(const Model& m, const State& s, int spring) {
  const Spring& sp = m.springs[spring];
  Vec6 fa, fb;
  double report = 0;
  static const std::vector<double> kNoCommands;
  elementForce(m, Element{true, spring, sp.body_a, sp.body_b, sp.joint}, bodyOrGround(s, sp.body_a),
               bodyOrGround(s, sp.body_b), kNoCommands, angleReference(sp, s), fa, fb, report);
  return report;
}

double springStretchAt(const Model& m, const State& s, int spring) {
  const Spring& sp = m.springs[spring];
  const BodyState& a = bodyOrGround(s, sp.body_a);
  const BodyState& b = bodyOrGround(s, sp.body_b);
  if (sp.type == SpringType::Linear)
    return (pointWorld(b, sp.end_b) - pointWorld(a, sp.end_a)).norm() - sp.rest;
  return jointCoordinateNear(angleJoint(m, sp), a, b, angleReference(sp, s)) - sp.rest;
}

double springLoadPowerAt(const Model& m, const State& s, int spring) {
  const Spring& sp = m.springs[spring];
  const BodyState& a = bodyOrGround(s, sp.body_a);
  const BodyState& b = bodyOrGround(s, sp.body_b);
  Vec6 fa, fb;
  double report = 0;
  static const std::vector<double> kNoCommands;
  elementForce(m, Element{true, spring, sp.body_a, sp.body_b, sp.joint}, a, b, kNoCommands, angleReference(sp, s),
               fa, fb, report);
  // Generalized force (world force, body torque) against the body's (v world, w body).
  return fa.head<3>().dot(a.v) + fa.tail<3>().dot(a.w) + fb.head<3>().dot(b.v) + fb.tail<3>().dot(b.w);
}

namespace {

// K and C are nonzero only within the stiff groups (the bodies springs and PD
// actuators join): only those blocks are cleared (and symmetrised, below).
void clearStiffBlocks(StepWorkspace& ws) {
  for (const std::vector<int>& g : ws.facts.stiff_groups)
    for (int bc : g) {
      ws.K_skew_v.segment<6>(6 * bc).setZero();
      for (int br : g) {
        ws.K.block<6, 6>(6 * br, 6 * bc).setZero();
        ws.C.block<6, 6>(6 * br, 6 * bc).setZero();
      }
    }
}

// Gravity, and the force and torque actuators: explicit.
void addGravityAndActuatorLoads(const Model& m, const State& s, StepWorkspace& ws, StepOutputs& out) {
  const std::vector<double>& commands = s.commands;
  const Vec3 g = m.settings.gravity;
  for (int i = 0; i < ws.nbodies; ++i) ws.F.segment<3>(6 * i) += m.bodies[i].mass * g;
  for (size_t i = 0; i < m.actuators.size(); ++i) {
    const Actuator& ac = m.actuators[i];
    if (ac.type == ActuatorType::Torque) {  // a pure moment about a body-fixed axis
      ws.F.segment<3>(6 * ac.body + 3) += commands[i] * ac.direction;
      out.actuator_effort[i] = commands[i];
      continue;
    }
    if (ac.type != ActuatorType::Force) continue;
    const BodyState& b = s.bodies[ac.body];
    const Vec3 f = b.q * (commands[i] * ac.direction);
    Vec6 gf = Vec6::Zero();
    addForceAt(gf, b, f, pointWorld(b, ac.point));
    ws.F.segment<6>(6 * ac.body) += gf;
    out.actuator_effort[i] = commands[i];
  }
}

Vec6 bodyVelocity(const State& s, int body) {
  Vec6 v;
  v << s.bodies[body].v, s.bodies[body].w;
  return v;
}

// An element's columns of K = dF/dq and C = dF/dv by central differences over
// the 6 velocity and 6 position DOF of each of its bodies (columns known to be
// exactly 0 skipped), and of a follower load's (K - K^T)/2 v_k into K_skew_v.
// a0, b0: its bodies' states; ref: its angle reference (elementForce).
void addElementDerivatives(const Model& m, const State& s, const Element& el, const BodyState& a0,
                           const BodyState& b0, double ref, bool damped, bool rotational,
                           bool follower, StepWorkspace& ws) {
  const std::vector<double>& commands = s.commands;
  const int bodies[2] = {el.body_a, el.body_b};
  for (int side = 0; side < 2; ++side) {
    const int bj = bodies[side];
    if (bj == kGround) continue;
    const double scale_x = 1e-7 * (1.0 + s.bodies[bj].x.norm());
    for (int pos = damped ? 0 : 1; pos < 2; ++pos) {
      for (int dof = rotational ? 3 : 0; dof < 6; ++dof) {
        const double eps = pos ? (dof < 3 ? scale_x : kTurnStep) : 1e-6 * (1.0 + s.bodies[bj].v.norm() + s.bodies[bj].w.norm());
        BodyState ap = a0, bp = b0, am = a0, bm = b0;
        perturb(side == 0 ? ap : bp, dof, eps, pos);
        perturb(side == 0 ? am : bm, dof, -eps, pos);
        Vec6 fap, fbp, fam, fbm;
        double r;
        elementForce(m, el, ap, bp, commands, ref, fap, fbp, r);
        elementForce(m, el, am, bm, commands, ref, fam, fbm, r);
        Eigen::MatrixXd& D = pos ? ws.K : ws.C;
        const int col = 6 * bj + dof;
        const Vec6 ka = (fap - fam) / (2 * eps), kb = (fbp - fbm) / (2 * eps);
        if (el.body_a != kGround) D.block<6, 1>(6 * el.body_a, col) += ka;
        if (el.body_b != kGround) D.block<6, 1>(6 * el.body_b, col) += kb;
        if (!follower || !pos) continue;
        // This column's share of (K - K^T)/2 v: column x v[col], minus (column . v) at col.
        const double v_col = bodyVelocity(s, bj)[dof];
        double along = 0;
        if (el.body_a != kGround) {
          ws.K_skew_v.segment<6>(6 * el.body_a) += (0.5 * v_col) * ka;
          along += ka.dot(bodyVelocity(s, el.body_a));
        }
        if (el.body_b != kGround) {
          ws.K_skew_v.segment<6>(6 * el.body_b) += (0.5 * v_col) * kb;
          along += kb.dot(bodyVelocity(s, el.body_b));
        }
        ws.K_skew_v[col] -= 0.5 * along;
      }
    }
  }
}

// A spring or PD actuator: its force on its bodies, its effort (actuators), and
// with_jacobians its share of K and C.
void addElement(const Model& m, const State& s, const Element& el, bool with_jacobians, StepWorkspace& ws,
                StepOutputs& out) {
  const BodyState& a0 = bodyOrGround(s, el.body_a);
  const BodyState& b0 = bodyOrGround(s, el.body_b);
  Vec6 fa, fb;
  double report = 0;
  const double ref = el.is_spring ? angleReference(m.springs[el.index], s) : s.joint_position[el.joint];
  elementForce(m, el, a0, b0, s.commands, ref, fa, fb, report);
  if (!el.is_spring) out.actuator_effort[el.index] = report;
  if (el.body_a != kGround) ws.F.segment<6>(6 * el.body_a) += fa;
  if (el.body_b != kGround) ws.F.segment<6>(6 * el.body_b) += fb;
  if (!with_jacobians) return;
  // Without damping the force does not depend on the velocities (they enter
  // multiplied by 0): its velocity columns are exactly 0 and are skipped.
  const bool damped = el.is_spring ? m.springs[el.index].damping != 0
                                   : m.actuators[el.index].kd != 0;
  // A torsion spring, and a PD actuator on a revolute joint, read only
  // orientations and angular velocities, and so do their body-fixed loads (a
  // world force R d, a body torque p x d): their columns of x and v are exactly
  // 0 as well, and are skipped.
  const bool rotational = el.is_spring ? m.springs[el.index].type == SpringType::Torsion
                                       : m.joints[el.joint].type != JointType::Prismatic;
  // An undamped linear spring's K in closed form (agrees with the differences
  // to their round-off, ~1e-10 of |K|, at a fraction of the cost).
  const bool follower = el.is_spring && !m.springs[el.index].loads.empty();
  if (el.is_spring && !damped && m.springs[el.index].type == SpringType::Linear && !follower &&
      addLinearSpringStiffness(m.springs[el.index], a0, b0, el.body_a, el.body_b, ws.K))
    return;
  // Body-fixed loads turn with their body: their K is not symmetric. Its symmetric
  // part goes into K (below) and the iteration matrix; the rest, (K - K^T)/2 v_k,
  // into K_skew_v, which the step adds explicitly (iteration_matrix.cpp): without
  // it a follower force through a spinning body's centre would turn the body.
  addElementDerivatives(m, s, el, a0, b0, ref, damped, rotational, follower, ws);
}

// Only the symmetric part of K and C enters the iteration matrix (it must stay SPD).
void symmetriseStiffBlocks(StepWorkspace& ws) {
  for (Eigen::MatrixXd* D : {&ws.K, &ws.C})
    for (const std::vector<int>& g : ws.facts.stiff_groups)
      for (int bc : g)
        for (int c = 6 * bc; c < 6 * bc + 6; ++c)
          for (int br : g)
            for (int r = std::max(6 * br, c + 1); r < 6 * br + 6; ++r) {
              const double avg = 0.5 * ((*D)(r, c) + (*D)(c, r));
              (*D)(r, c) = avg;
              (*D)(c, r) = avg;
            }
}

}  // namespace

void computeForces(const Model& m, const State& s, StepWorkspace& ws, StepOutputs& out,
                   bool with_jacobians) {
  ws.F.setZero();
  if (with_jacobians) clearStiffBlocks(ws);
  addGravityAndActuatorLoads(m, s, ws, out);
  // Springs and PD actuators, with their stiffness and damping.
  for (size_t i = 0; i < m.springs.size(); ++i)
    addElement(m, s,
               Element{true, static_cast<int>(i), m.springs[i].body_a, m.springs[i].body_b,
                       m.springs[i].type == SpringType::Torsion ? m.springs[i].joint : -1},
               with_jacobians, ws, out);
  for (size_t i = 0; i < m.actuators.size(); ++i) {
    const Actuator& ac = m.actuators[i];
    if (ac.type != ActuatorType::Position) continue;
    const Joint& j = m.joints[ac.joint];
    addElement(m, s, Element{false, static_cast<int>(i), j.body_a, j.body_b, ac.joint}, with_jacobians, ws, out);
  }
  if (with_jacobians) symmetriseStiffBlocks(ws);
}

}  // namespace nscd
