// The time step as a pipeline of plain stages (see step_workspace.hpp):
// forces -> free velocity -> constraint rows -> Delassus operator -> solve ->
// update -> projection -> reports.
#include "nscd_sim/simulator.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "step_workspace.hpp"

namespace nscd {
namespace {

bool hasStiffElements(const Model& m) {
  if (!m.springs.empty()) return true;
  for (const Actuator& a : m.actuators)
    if (a.type == ActuatorType::Position) return true;
  return false;
}

int bilateralRowCount(const Model& m, std::vector<int>& joint_base, std::vector<int>& act_base) {
  int rows = 0;
  joint_base.assign(m.joints.size(), -1);
  act_base.assign(m.actuators.size(), -1);
  for (size_t j = 0; j < m.joints.size(); ++j) {
    if (m.joints[j].clearance >= 0) continue;
    joint_base[j] = rows;
    rows += m.joints[j].type == JointType::Fixed ? 6 : 5;
  }
  for (size_t a = 0; a < m.actuators.size(); ++a) {
    if (m.actuators[a].type != ActuatorType::Prescribed) continue;
    act_base[a] = rows;
    rows += m.actuators[a].joint >= 0 ? 1 : 6;
  }
  return rows;
}

// Residual above which an unconverged frictional answer is replaced (see step()).
constexpr double kFrictionlessFallbackResidual = 1e-3;
// Re-solves per step for contacts closed by the answer (activateLateContacts).
constexpr int kLateActivationRounds = 3;

// Kinetic energy of one body (v world, w body frame).
double bodyKineticEnergy(const Body& body, const Vec3& v, const Vec3& w) {
  return 0.5 * (body.mass * v.squaredNorm() + w.dot(body.inertia * w));
}

// Kinetic energy of the generalized velocity v (linear world, angular body frame).
double kineticEnergyOf(const Model& m, const StepWorkspace& ws, const Eigen::VectorXd& v) {
  double k = 0;
  for (int b = 0; b < ws.nbodies; ++b)
    k += bodyKineticEnergy(m.bodies[b], v.segment<3>(6 * b), v.segment<3>(6 * b + 3));
  return k;
}

// Gravity and spring potential energies of the positions in s (kinetic = 0).
EnergyReport potentialEnergyOf(const Model& m, const State& s) {
  EnergyReport e;
  for (size_t i = 0; i < m.bodies.size(); ++i)
    e.gravity -= m.bodies[i].mass * m.settings.gravity.dot(s.bodies[i].x);
  for (const Spring& sp : m.springs) {
    double stretch;
    if (sp.type == SpringType::Linear) {
      stretch = (bodyPointWorld(s, sp.body_b, sp.end_b) - bodyPointWorld(s, sp.body_a, sp.end_a)).norm() - sp.rest;
    } else {
      stretch = jointPosition(m, s, sp.joint) - sp.rest;
    }
    e.springs += 0.5 * sp.stiffness * stretch * stretch;
  }
  return e;
}

double kineticEnergyOf(const Model& m, const State& s) {
  double k = 0;
  for (size_t i = 0; i < m.bodies.size(); ++i)
    k += bodyKineticEnergy(m.bodies[i], s.bodies[i].v, s.bodies[i].w);
  return k;
}

// Takes `amount` (J) out of the kinetic energy of the state by one common
// factor on every velocity (homogeneous velocity constraints stay satisfied);
// all of it if there is less. Returns what was taken.
double removeKineticEnergy(const Model& m, State& s, double amount) {
  const double k = kineticEnergyOf(m, s);
  if (!(k > 0)) return 0;
  const double f = amount < k ? std::sqrt(1 - amount / k) : 0.0;
  for (BodyState& b : s.bodies) {
    b.v *= f;
    b.w *= f;
  }
  return std::min(amount, k);
}

// Whether the impulses of an impact with restitution add energy, by either of
// two measures, each compared with K(v_free):
// - the kinetic energy they add, Phi = sum_c P_c.u+_c - P.W.P/2 (the change
//   K(v+) - K(v_free) minus the work of the bilateral rows' targets). With e = 0
//   every term is <= 0 (u_N+ P_N = 0, friction opposes u_T+);
// - their work over the step, sum_c P_c.(theta u+_c + (1 - theta) u_k,c): the
//   positions move with that velocity, so with gravity alone this is the step's
//   energy change. It can be positive where a contact separates at the start of
//   the step, or where friction that stops a sliding point at its end points
//   along the sliding at its start.
bool impactGainsEnergy(const Model& m, StepWorkspace& ws, int r) {
  bool any_restitution = false;
  for (const ConstraintBlock& blk : ws.blocks)
    any_restitution = any_restitution || (blk.kind != BlockKind::Bilateral && blk.e > 0);
  if (!any_restitution) return false;
  const auto G = ws.G.topRows(r);
  const double theta = m.settings.theta;
  double post = 0, wpp = 0, work = 0;
  for (const ConstraintBlock& blk : ws.blocks) {
    for (int k = 0; k < blk.size; ++k) {
      const int i = blk.row + k;
      const double u_new = G.row(i).dot(ws.vnew);
      const double u_free = G.row(i).dot(ws.vfree);
      wpp += ws.P[i] * (u_new - u_free);
      if (blk.kind == BlockKind::Bilateral) continue;
      post += ws.P[i] * u_new;
      work += ws.P[i] * (theta * u_new + (1 - theta) * G.row(i).dot(ws.vk));
    }
  }
  const double phi = post - 0.5 * wpp;
  const double tol = 1e-12 * kineticEnergyOf(m, ws, ws.vfree) + 1e-300;
  return (std::isfinite(phi) && phi > tol) || (std::isfinite(work) && work > tol);
}

// M^-1 restricted to the allowed directions: B (B^T A B)^-1 B^T (B = I unless planar).
bool reducedInverse(const Eigen::MatrixXd& A, StepWorkspace& ws, Eigen::MatrixXd& out) {
  if (!ws.planar) {
    ws.llt.compute(A);
    if (ws.llt.info() != Eigen::Success) return false;
    out.setIdentity();
    ws.llt.solveInPlace(out);
    return true;
  }
  ws.AB.noalias() = A * ws.basis;
  ws.red.noalias() = ws.basis.transpose() * ws.AB;
  ws.llt.compute(ws.red);
  if (ws.llt.info() != Eigen::Success) return false;
  ws.BT = ws.basis.transpose();
  ws.llt.solveInPlace(ws.BT);
  out.noalias() = ws.basis * ws.BT;
  return true;
}

}  // namespace

Simulator::Simulator(Model model) : model_(std::move(model)), ws_(new StepWorkspace) {
  StepWorkspace& ws = *ws_;
  const Model& m = model_;
  ws.nbodies = static_cast<int>(m.bodies.size());
  ws.n = 6 * ws.nbodies;
  const int n = ws.n;
  const int bil_rows = bilateralRowCount(m, ws.joint_row_base, ws.actuator_row_base);
  const int contact_slots = static_cast<int>(m.contacts.size()) * kMaxPointsPerPair +
                            static_cast<int>(m.clearance_joints.size()) * kMaxClearancePoints;
  ws.contact_slot_base_clearance = static_cast<int>(m.contacts.size()) * kMaxPointsPerPair;
  ws.max_rows = bil_rows + 3 * contact_slots;
  const int mr = std::max(ws.max_rows, 1);
  ws.F = Eigen::VectorXd::Zero(n);
  ws.K = Eigen::MatrixXd::Zero(n, n);
  ws.C = Eigen::MatrixXd::Zero(n, n);
  ws.A = Eigen::MatrixXd::Zero(n, n);
  ws.Minv = Eigen::MatrixXd::Zero(n, n);
  ws.Mproj = Eigen::MatrixXd::Zero(n, n);
  ws.rhs = ws.vk = ws.vfree = ws.vnew = ws.dv = Eigen::VectorXd::Zero(n);
  ws.saved_bodies.resize(m.bodies.size());
  ws.predicted.bodies.resize(m.bodies.size());
  ws.G = Eigen::MatrixXd::Zero(mr, n);
  ws.Y = Eigen::MatrixXd::Zero(n, mr);
  ws.W = Eigen::MatrixXd::Zero(mr, mr);
  ws.b = ws.P = Eigen::VectorXd::Zero(mr);
  ws.blocks.reserve(mr);
  ws.deferred.reserve(contact_slots);
  ws.row_bodies.assign(mr, {kGround, kGround});
  ws.problem.reserve(mr);
  ws.reports.reserve(mr);
  ws.warm.assign(contact_slots, Eigen::Vector3d::Zero());
  ws.warm_valid.assign(contact_slots, 0);
  ws.warm_bilateral.assign(bil_rows, 0.0);
  ws.phi_hint.assign(2 * m.clearance_joints.size(), std::numeric_limits<double>::quiet_NaN());
  ws.actuator_effort.assign(m.actuators.size(), 0.0);
  ws.rates.assign(m.actuators.size(), 0.0);
  ws.zero_rates.assign(m.actuators.size(), 0.0);
  ws.spring_force.assign(m.springs.size(), 0.0);
  ws.pair_gap.assign(m.contacts.size(), 0.0);
  ws.pair_fn.assign(m.contacts.size(), 0.0);
  ws.pair_ft.assign(m.contacts.size(), 0.0);
  ws.cj_fn.assign(m.clearance_joints.size(), 0.0);

  // Allowed velocity directions: all, or the x-y plane motions (3 per body).
  const bool planar = m.settings.planar == PlanarMode::XY;
  ws.planar = planar;
  ws.basis = Eigen::MatrixXd::Zero(n, planar ? 3 * ws.nbodies : n);
  for (int i = 0; i < ws.nbodies; ++i) {
    if (!planar) {
      ws.basis.block<6, 6>(6 * i, 6 * i).setIdentity();
    } else {
      ws.basis(6 * i + 0, 3 * i + 0) = 1;
      ws.basis(6 * i + 1, 3 * i + 1) = 1;
      // rotation about world z, in body coordinates (constant under planar motion)
      ws.basis.block<3, 1>(6 * i + 3, 3 * i + 2) =
          m.bodies[i].initial_pose.q.conjugate() * Vec3::UnitZ();
    }
  }
  ws.AB = Eigen::MatrixXd::Zero(n, ws.basis.cols());
  ws.red = Eigen::MatrixXd::Zero(ws.basis.cols(), ws.basis.cols());
  ws.BT = Eigen::MatrixXd::Zero(ws.basis.cols(), n);
  pair_ft_vec_.assign(m.contacts.size(), Vec3::Zero());
  // Constant mass matrix and its (planar-projected) inverse.
  for (int i = 0; i < ws.nbodies; ++i) {
    ws.A.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
    ws.A.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
  }
  if (!reducedInverse(ws.A, ws, ws.Mproj))
    throw std::runtime_error(m.source_file + ": mass matrix is not positive definite");
  ws.Minv = ws.Mproj;

  // Initial state.
  state_.t = 0;
  state_.bodies.resize(ws.nbodies);
  for (int i = 0; i < ws.nbodies; ++i) {
    const Body& b = m.bodies[i];
    BodyState& s = state_.bodies[i];
    s.x = b.initial_pose.p;
    s.q = b.initial_pose.q.normalized();
    s.v = b.initial_velocity;
    s.w = s.q.conjugate() * b.initial_angular_velocity;
    if (planar) {  // keep only the in-plane part of the initial velocity
      s.v.z() = 0;
      s.w = s.q.conjugate() * Vec3(0, 0, (s.q * s.w).z());
    }
  }
  commands_.resize(m.actuators.size());
  for (size_t i = 0; i < m.actuators.size(); ++i) commands_[i] = m.actuators[i].initial_command;
  prev_commands_ = commands_;

  // Assembly: remove loop-closure mismatch and initial penetrations.
  double violation = 0;
  const double tol = m.settings.projection_tolerance;
  projectPositions(m, state_, commands_, ws, 200, tol, violation);
  if (violation > tol)
    throw std::runtime_error(m.source_file + ": assembly failed: constraint violation " +
                             std::to_string(violation) + " after 200 projection passes");
  // Initial velocities consistent with... left as given: the first step enforces H v = 0.
  initial_state_ = state_;
}

Simulator::~Simulator() = default;

void Simulator::reset() {
  state_ = initial_state_;
  for (size_t i = 0; i < model_.actuators.size(); ++i)
    commands_[i] = model_.actuators[i].initial_command;
  prev_commands_ = commands_;
  StepWorkspace& ws = *ws_;
  std::fill(ws.warm_valid.begin(), ws.warm_valid.end(), 0);
  std::fill(ws.warm_bilateral.begin(), ws.warm_bilateral.end(), 0.0);
  ws.reports.clear();
  ws.stats = StepStats();
  ws.penetration_pending = false;
  std::fill(ws.phi_hint.begin(), ws.phi_hint.end(), std::numeric_limits<double>::quiet_NaN());
}

bool Simulator::setCommand(int actuator, double value) {
  if (actuator < 0 || actuator >= static_cast<int>(commands_.size()) || !std::isfinite(value))
    return false;
  commands_[actuator] = value;
  return true;
}

StepStatus Simulator::step() {
  const Model& m = model_;
  StepWorkspace& ws = *ws_;
  const Settings& set = m.settings;
  const double h = set.dt, theta = set.theta;
  const int n = ws.n;
  ws.blocks.clear();
  ws.rows = 0;
  for (size_t i = 0; i < commands_.size(); ++i) ws.rates[i] = (commands_[i] - prev_commands_[i]) / h;

  // 1. forces, iteration matrix, free velocity
  const bool stiff = hasStiffElements(m);
  computeForces(m, state_, commands_, ws, stiff);
  stateVelocities(state_, ws.vk);
  ws.rhs.noalias() = h * ws.F;
  if (stiff) {
    for (int i = 0; i < ws.nbodies; ++i) {
      ws.A.block<6, 6>(6 * i, 6 * i).setZero();
      ws.A.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
      ws.A.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
    }
    // A = M - h theta C - h^2 theta^2 K   (off-diagonal blocks come from C, K only)
    for (int c = 0; c < n; ++c)
      for (int r = 0; r < n; ++r) {
        const bool diag_block = (r / 6) == (c / 6);
        const double base = diag_block ? ws.A(r, c) : 0.0;
        ws.A(r, c) = base - h * theta * ws.C(r, c) - h * h * theta * theta * ws.K(r, c);
      }
    ws.rhs.noalias() += (h * h * theta) * ws.K * ws.vk;
    if (!reducedInverse(ws.A, ws, ws.Minv)) ws.Minv = ws.Mproj;  // fall back: explicit
  }
  ws.vfree = ws.vk;
  ws.vfree.noalias() += ws.Minv * ws.rhs;
  addGyroscopicImpulses(m, h, ws);

  // 2. constraint rows. Contact rows are built at q_k + ahead v_k (by default
  // the end of the step as predicted by v_k, Siconos's convention): a contact
  // that slides around a curved surface, or lies on a rotating body far from
  // its centre of mass, then no longer drifts by O(h^2) per step (see
  // docs/siconos_comparison.md).
  appendBilateralBlocks(m, state_, commands_, ws.rates, ws);
  const double ahead = set.contact_prediction * h;
  if (ahead > 0) predictState(state_, ahead, ws.predicted);
  appendContactBlocks(m, state_, h, false, 0.0, ahead > 0, ws);

  // 3-4. Delassus operator, local free velocities, solve
  StepStats& st = ws.stats;
  st = StepStats();
  ws.penetration_pending = false;
  ws.reports.clear();
  SolverOptions opt;
  opt.tolerance = set.tolerance;
  opt.max_iterations = set.max_iterations;

  // Assembles W, b and the blocks of rows [0, ws.rows) and solves. Rows below
  // `kept` start from the current ws.P (a re-solve), the others from the warm
  // start cache. Leaves ws.vnew.
  const auto assembleAndSolve = [&](int kept) {
    const int r = ws.rows;
    auto G = ws.G.topRows(r);
    assembleDelassus(ws.Minv, !stiff, ws, kept, r);  // rows below `kept` are already there
    ws.b.head(r).noalias() = G * ws.vfree;
    ws.problem.clear();
    st.active_contacts = 0;
    for (ConstraintBlock& blk : ws.blocks) {
      ProblemBlock pb;
      pb.kind = blk.kind;
      pb.row = blk.row;
      pb.size = blk.size;
      pb.mu = blk.mu;
      ws.problem.push_back(pb);
      const bool warm = blk.row >= kept;
      if (blk.kind == BlockKind::Bilateral) {
        for (int k = 0; k < blk.size; ++k) ws.b[blk.row + k] -= blk.target[k];
        const int base = blk.joint >= 0 ? ws.joint_row_base[blk.joint]
                                        : ws.actuator_row_base[blk.actuator];
        if (warm)
          for (int k = 0; k < blk.size; ++k) ws.P[blk.row + k] = ws.warm_bilateral[base + k];
      } else {
        ++st.active_contacts;
        // Newton impact law: U_N+ >= -e U_N- for approaching contacts.
        const double un_k = G.row(blk.row).dot(ws.vk);
        if (un_k < 0) ws.b[blk.row] += blk.e * un_k;
        if (warm) {
          const bool valid = blk.slot >= 0 && ws.warm_valid[blk.slot] != 0;
          for (int k = 0; k < blk.size; ++k) ws.P[blk.row + k] = valid ? ws.warm[blk.slot][k] : 0.0;
        }
        if (set.planar == PlanarMode::XY && blk.size == 3) {
          // The out-of-plane tangent row is void: decouple it so P_T2 stays 0.
          const int t2 = blk.row + 2;
          ws.W.row(t2).head(r).setZero();
          ws.W.col(t2).head(r).setZero();
          ws.W(t2, t2) = std::max(ws.W(blk.row + 1, blk.row + 1), 1e-300);
          ws.b[t2] = 0;
          ws.P[t2] = 0;
        }
      }
    }
    // Takes the Newton impact shift back out of b: the plastic problem.
    const auto removeRestitution = [&] {
      for (const ConstraintBlock& blk : ws.blocks) {
        if (blk.kind == BlockKind::Bilateral) continue;
        const double un_k = G.row(blk.row).dot(ws.vk);
        if (un_k < 0) ws.b[blk.row] -= blk.e * un_k;
      }
    };
    // v+ = v_free + Ŵ Gᵀ P
    const auto applyImpulses = [&] {
      ws.vnew = ws.vfree;
      ws.vnew.noalias() += ws.Y.leftCols(r) * ws.P.head(r);
    };
    SolverOptions o = opt;
    SolverReport rep =
        ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, o, ws.P.head(r));
    if (!ws.P.head(r).allFinite() && ws.W.topLeftCorner(r, r).allFinite() && ws.b.head(r).allFinite()) {
      // Robustness: a non-finite answer from the Newton stage is never applied;
      // solve again cold by plain NSGS.
      ws.P.head(r).setZero();
      o.method = SolverMethod::NSGS;
      rep = ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, o, ws.P.head(r));
    }
    applyImpulses();
    bool plastic = false;
    if (st.active_contacts > 0 && impactGainsEnergy(m, ws, r)) {
      // Newton's law at several coupled frictional points can add kinetic energy
      // (it is only proven dissipative for one point), and with theta = 1/2 the
      // impulses can do positive work over the step. The impact is then taken as
      // plastic (e = 0); see impactGainsEnergy.
      removeRestitution();
      rep = ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, o, ws.P.head(r));
      applyImpulses();
      plastic = st.plastic_fallback = true;
    }
    if (!rep.converged && !(rep.residual <= kFrictionlessFallbackResidual) && st.active_contacts > 0) {
      // The frictional problem was not solved (it may have no solution: Coulomb
      // friction with restitution at coupled points). Far from a solution the
      // iterate can drive bodies through each other, so this step is taken
      // frictionless and plastic: a convex problem, always solvable. The
      // problem blocks are rebuilt by the next assembly.
      if (!plastic) removeRestitution();
      for (ProblemBlock& pb : ws.problem) pb.mu = 0;
      const SolverReport rep0 =
          ws.solver.solve(ws.W.topLeftCorner(r, r), ws.b.head(r), ws.problem, o, ws.P.head(r));
      if (ws.P.head(r).allFinite()) {
        rep.iterations += rep0.iterations;
        rep.residual = rep0.residual;
        rep.converged = false;  // the step's own problem stays unsolved: reported
        applyImpulses();
        st.frictionless_fallback = true;
      }
    }
    if (!rep.converged && !(rep.residual <= kFrictionlessFallbackResidual)) {
      // Still far from a solution (the problem may have none: coupled 3D joints
      // at tiny clearances): such an answer must not add kinetic energy. Along
      // its direction, dK(a) = a P.u_free + a^2/2 P.W.P; take the a in [0, 1]
      // that minimises it, so dK <= 0. Prescribed motions are scaled too.
      double pu = 0, pwp = 0;
      for (int i = 0; i < r; ++i) {
        pu += ws.P[i] * G.row(i).dot(ws.vfree);
        pwp += ws.P[i] * G.row(i).dot(ws.vnew - ws.vfree);
      }
      if (std::isfinite(pu) && std::isfinite(pwp) &&
          pu + 0.5 * pwp > 1e-12 * kineticEnergyOf(m, ws, ws.vfree)) {
        const double a = pwp > 0 ? std::min(1.0, std::max(0.0, -pu / pwp)) : 0.0;
        ws.P.head(r) *= a;
        applyImpulses();
        st.energy_capped = true;
      }
    }
    return rep;
  };

  if (ws.rows > 0) {
    SolverReport rep = assembleAndSolve(0);
    // Candidates left out because neither v_k nor v_free closed them can be
    // closed by the impulses at the others (a light body between two joints is
    // kicked from one into the other): they join and the problem is solved
    // again from this answer.
    for (int round = 0; round < kLateActivationRounds; ++round) {
      const int kept = ws.rows;
      const int added = activateLateContacts(m, state_, h, ws);
      if (added == 0) break;
      st.late_contacts += added;
      const int iterations = rep.iterations;
      rep = assembleAndSolve(kept);
      rep.iterations += iterations;
    }
    st.iterations = rep.iterations;
    st.residual = rep.residual;
    st.converged = rep.converged;
  } else {
    ws.vnew = ws.vfree;
  }
  st.rows = ws.rows;

  // Warm starts for the next step: exactly this step's active set.
  std::fill(ws.warm_valid.begin(), ws.warm_valid.end(), 0);
  std::fill(ws.pair_fn.begin(), ws.pair_fn.end(), 0.0);
  std::fill(ws.cj_fn.begin(), ws.cj_fn.end(), 0.0);
  for (Vec3& f : pair_ft_vec_) f.setZero();
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.kind == BlockKind::Bilateral) {
      const int base = blk.joint >= 0 ? ws.joint_row_base[blk.joint]
                                      : ws.actuator_row_base[blk.actuator];
      for (int k = 0; k < blk.size; ++k) ws.warm_bilateral[base + k] = ws.P[blk.row + k];
      if (blk.actuator >= 0) {
        // The effort a prescribed motion needs: the impulse along its driven row.
        ws.actuator_effort[blk.actuator] = ws.P[blk.row] / h;
      }
      continue;
    }
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int k = 0; k < blk.size; ++k) p[k] = ws.P[blk.row + k];
    ws.warm[blk.slot] = p;
    ws.warm_valid[blk.slot] = 1;
    ContactReport rep;
    rep.source = blk.source;
    rep.clearance = blk.clearance;
    rep.feature = blk.cp.feature;
    rep.body_a = blk.body_a;
    rep.body_b = blk.body_b;
    rep.point = blk.cp.point_b;
    rep.normal = blk.cp.normal;
    rep.fn = p[0] / h;
    rep.ft = (p[1] * blk.t1 + p[2] * blk.t2) / h;
    rep.sliding = blk.size == 3 && p[0] > 0 && p.tail<2>().norm() >= blk.mu * p[0] * (1 - 1e-6);
    // Gap at the end of the step, to first order in the motion.
    const double un = ws.G.row(blk.row).dot(theta * ws.vnew + (1 - theta) * ws.vk);
    rep.gap = blk.cp.gap + h * un;
    ws.reports.push_back(rep);
    if (blk.clearance) {
      ws.cj_fn[blk.source] += rep.fn;
    } else {
      ws.pair_fn[blk.source] += rep.fn;
      pair_ft_vec_[blk.source] += rep.ft;
    }
  }
  for (size_t p = 0; p < pair_ft_vec_.size(); ++p) ws.pair_ft[p] = pair_ft_vec_[p].norm();

  // 5. update
  integratePositions(state_, ws.vk, ws.vnew, h, theta);
  setStateVelocities(state_, ws.vnew);
  state_.t += h;
  prev_commands_ = commands_;

  // 6. projection
  double violation = 0;
  if (set.projection) {
    // Without actuators nothing puts energy in: the potential energy the
    // projection adds (it lifts a body that drifted into a contact; the exact
    // motion never did) is a discretisation artefact, taken back from the
    // kinetic energy so that such a scene never gains energy.
    const bool no_input = m.actuators.empty();
    const double pe_before = no_input ? potentialEnergyOf(m, state_).total() : 0.0;
    st.projection_passes = projectPositions(m, state_, commands_, ws,
                                            set.projection_max_iterations,
                                            set.projection_tolerance, violation);
    if (no_input && st.projection_passes > 0) {
      const double gain = potentialEnergyOf(m, state_).total() - pe_before;
      if (gain > 0) st.projection_energy_removed = removeKineticEnergy(m, state_, gain);
    }
    st.max_penetration = 0;
    for (const ConstraintBlock& blk : ws.blocks)
      if (blk.kind != BlockKind::Bilateral) st.max_penetration = std::max(st.max_penetration, -blk.cp.gap);
  } else {
    // Measured when asked for (stats()): it costs a geometry pass, as much as
    // the contact search itself, and most callers never read it.
    st.max_penetration = 0;
    ws.penetration_pending = true;
  }
  ws.blocks.clear();
  ws.rows = 0;

  bool finite = ws.vnew.allFinite();
  for (const BodyState& b : state_.bodies)
    finite = finite && b.x.allFinite() && b.q.coeffs().allFinite();
  if (!finite) return StepStatus::NonFinite;
  return st.converged ? StepStatus::Ok : StepStatus::NotConverged;
}

double Simulator::actuatorEffort(int actuator) const { return ws_->actuator_effort[actuator]; }
double Simulator::springForce(int spring) const { return springForceAt(model_, state_, spring); }
const StepStats& Simulator::stats() const {
  StepWorkspace& ws = *ws_;
  if (ws.penetration_pending) {  // the last step had no projection (see step())
    ws.penetration_pending = false;
    ws.phi_saved = ws.phi_hint;  // a query must not change the trajectory
    ws.stats.max_penetration = measureViolation(model_, state_, commands_, ws);
    ws.phi_hint = ws.phi_saved;
    ws.blocks.clear();
    ws.rows = 0;
  }
  return ws.stats;
}
const std::vector<ContactReport>& Simulator::contacts() const { return ws_->reports; }

EnergyReport Simulator::energy() const {
  EnergyReport e = potentialEnergyOf(model_, state_);
  e.kinetic = kineticEnergyOf(model_, state_);
  return e;
}

Pose Simulator::bodyPose(int body) const {
  if (body == kGround) return Pose();
  return Pose{state_.bodies[body].x, state_.bodies[body].q};
}

Pose Simulator::linkPose(int link) const {
  const Link& l = model_.links[link];
  return bodyPose(l.body) * l.in_body;
}

Vec3 Simulator::angularVelocityWorld(int body) const {
  return state_.bodies[body].q * state_.bodies[body].w;
}

namespace {
// Journal axis offset from the bearing centre, in the bearing's mid-plane (world).
Vec3 eccentricityVector(const State& s, const ClearanceJoint& cj, Vec3* ref, Vec3* axis) {
  const Pose pb = cj.bearing_body == kGround ? Pose() : Pose{s.bodies[cj.bearing_body].x, s.bodies[cj.bearing_body].q};
  const Pose pj = cj.journal_body == kGround ? Pose() : Pose{s.bodies[cj.journal_body].x, s.bodies[cj.journal_body].q};
  const Vec3 c = pb.apply(cj.bearing_center), n = pb.rotate(cj.bearing_axis);
  const Vec3 o = pj.apply(cj.journal_center), a = pj.rotate(cj.journal_axis);
  const double an = a.dot(n);
  const Vec3 p = std::abs(an) > 1e-12 ? Vec3(o + ((c - o).dot(n) / an) * a) : o;
  Vec3 e = p - c;
  e -= e.dot(n) * n;
  if (ref) *ref = pb.rotate(cj.bearing_ref);
  if (axis) *axis = n;
  return e;
}
}  // namespace

double Simulator::clearanceEccentricity(int cj) const {
  const ClearanceJoint& c = model_.clearance_joints[cj];
  return eccentricityVector(state_, c, nullptr, nullptr).norm() / c.radial;
}

double Simulator::clearanceEccentricityAngle(int cj) const {
  Vec3 ref, n;
  const Vec3 e = eccentricityVector(state_, model_.clearance_joints[cj], &ref, &n);
  return std::atan2(e.dot(n.cross(ref)), e.dot(ref));
}

double Simulator::clearanceNormalForce(int cj) const { return ws_->cj_fn[cj]; }

double Simulator::contactGap(int pair) const {
  const ContactPair& cp = model_.contacts[pair];
  const Pose pa = bodyPose(cp.a.body) * cp.a.pose;
  const Pose pb = bodyPose(cp.b.body) * cp.b.pose;
  ContactPoint pts[kMaxPointsPerPair];
  const int np = collide(cp.a, pa, cp.b, pb, 1e300, pts);
  double g = std::numeric_limits<double>::infinity();
  for (int k = 0; k < np; ++k) g = std::min(g, pts[k].gap);
  return g;
}

double Simulator::contactNormalForce(int pair) const { return ws_->pair_fn[pair]; }
double Simulator::contactTangentialForce(int pair) const { return ws_->pair_ft[pair]; }

double Simulator::constraintViolation() const {
  double bil = 0;
  // A query must not change the trajectory: keep the ring-angle hints of the step.
  ws_->phi_saved = ws_->phi_hint;
  const double pen = measureViolation(model_, state_, commands_, *ws_, &bil);
  ws_->phi_hint = ws_->phi_saved;
  ws_->blocks.clear();
  ws_->rows = 0;
  return std::max(pen, bil);
}

}  // namespace nscd
