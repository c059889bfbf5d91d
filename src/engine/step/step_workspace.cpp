// Set-up: every buffer of the step sized once for the model (a step allocates
// nothing), the facts of the model the stages need, and the initial state.
#include <limits>
#include <stdexcept>

#include "geometry/contact_pair.hpp"
#include "step_stages.hpp"

namespace nscd {
namespace {

// Bilateral rows of the ideal joints and prescribed actuators, and the first
// warm-start slot of each.
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
    rows += m.actuators[a].joint >= 0 || m.actuators[a].axis_only ? 1 : 6;
  }
  return rows;
}

// Springs and PD actuators couple bodies and need the iteration matrix.
bool hasStiffElements(const Model& m) {
  if (!m.springs.empty()) return true;
  for (const Actuator& a : m.actuators)
    if (a.type == ActuatorType::Position) return true;
  return false;
}

// Connected components of the bodies joined by springs and PD actuators.
void findStiffGroups(const Model& m, ModelFacts& f) {
  const int nb = static_cast<int>(m.bodies.size());
  std::vector<int> parent(nb);
  for (int i = 0; i < nb; ++i) parent[i] = i;
  std::vector<char> stiff(nb, 0);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  auto join = [&](int a, int b) {
    if (a != kGround) stiff[a] = 1;
    if (b != kGround) stiff[b] = 1;
    if (a == kGround || b == kGround) return;
    parent[root(a)] = root(b);
  };
  for (const Spring& sp : m.springs) join(sp.body_a, sp.body_b);
  for (const Actuator& ac : m.actuators)
    if (ac.type == ActuatorType::Position) join(m.joints[ac.joint].body_a, m.joints[ac.joint].body_b);
  f.stiff_groups.clear();
  std::vector<int> group_of_root(nb, -1);
  for (int i = 0; i < nb; ++i) {  // ascending bodies: each group ascending
    if (!stiff[i]) continue;
    int& g = group_of_root[root(i)];
    if (g < 0) {
      g = static_cast<int>(f.stiff_groups.size());
      f.stiff_groups.emplace_back();
    }
    f.stiff_groups[g].push_back(i);
  }
  f.coupled.assign(nb, {});
  for (int i = 0; i < nb; ++i) f.coupled[i] = {i};
  for (const std::vector<int>& g : f.stiff_groups)
    for (int i : g) f.coupled[i] = g;
  f.coupled_mask.assign(nb, 0);
  for (int i = 0; i < nb && nb <= 64; ++i)
    for (int c : f.coupled[i]) f.coupled_mask[i] |= std::uint64_t{1} << c;
}

// The facts of the model the stages read: row and slot counts, stiff groups,
// which bodies are prescribed, whether the rows depend on the poses only.
void collectModelFacts(const Model& m, ModelFacts& f) {
  f.bilateral_rows = bilateralRowCount(m, f.joint_row_base, f.actuator_row_base);
  f.contact_slots = static_cast<int>(m.contacts.size()) * kMaxPointsPerPair +
                    static_cast<int>(m.clearance_joints.size()) * kMaxClearancePoints;
  f.contact_slot_base_clearance = static_cast<int>(m.contacts.size()) * kMaxPointsPerPair;
  f.stiff = hasStiffElements(m);
  f.planar = m.settings.planar == PlanarMode::XY;
  f.pair_reach.clear();
  for (const ContactPair& pair : m.contacts) f.pair_reach.push_back({shapeReach(pair.a), shapeReach(pair.b)});
  findStiffGroups(m, f);
  // A body driven with constrain="axis" counts too: scaling its velocity to take
  // energy back would break the prescribed rate along its axis.
  f.prescribed_body.assign(m.bodies.size(), 0);
  for (const Actuator& ac : m.actuators) {
    if (ac.type != ActuatorType::Prescribed) continue;
    const int body = ac.joint >= 0 ? m.joints[ac.joint].body_b : ac.body;
    if (body >= 0) f.prescribed_body[body] = 1;
  }
  f.rows_follow_poses = f.contact_slots == 0;
  for (const Actuator& ac : m.actuators) f.rows_follow_poses = f.rows_follow_poses && ac.type != ActuatorType::Prescribed;
  f.rows_written_whole.assign(m.joints.size(), 0);
  for (size_t j = 0; j < m.joints.size(); ++j) {
    const Joint& joint = m.joints[j];
    f.rows_written_whole[j] =
        joint.clearance < 0 && joint.type == JointType::Revolute && joint.body_a != joint.body_b;
  }
}

// Every buffer of the step at its largest size: n = 6 per body, up to max_rows
// constraint rows (at least one, so that no buffer is empty).
void sizeStepBuffers(const Model& m, StepWorkspace& ws) {
  const ModelFacts& f = ws.facts;
  const int n = ws.n;
  ws.max_rows = f.bilateral_rows + 3 * f.contact_slots;
  const int mr = std::max(ws.max_rows, 1);
  ws.F = Eigen::VectorXd::Zero(n);
  ws.K_skew_v = Eigen::VectorXd::Zero(n);
  ws.K = Eigen::MatrixXd::Zero(n, n);
  ws.C = Eigen::MatrixXd::Zero(n, n);
  ws.A = Eigen::MatrixXd::Zero(n, n);
  ws.iteration_inverse = Eigen::MatrixXd::Zero(n, n);
  ws.mass_inverse = Eigen::MatrixXd::Zero(n, n);
  ws.rhs = ws.vk = ws.vfree = ws.vnew = ws.gyro_impulse = ws.dq = Eigen::VectorXd::Zero(n);
  ws.saved_bodies.resize(m.bodies.size());
  ws.unprojected_bodies.resize(m.bodies.size());
  ws.projection_turn.resize(m.bodies.size());
  ws.rows_key.resize(m.bodies.size());
  ws.rows_keyed = false;
  ws.saved_dq.setZero(ws.n);
  ws.retry_P.setZero(mr);
  ws.retry_b.setZero(mr);
  ws.predicted.bodies.resize(m.bodies.size());
  ws.omega_world.assign(m.bodies.size(), Vec3::Zero());
  ws.G = Eigen::MatrixXd::Zero(mr, n);
  ws.Y = Eigen::MatrixXd::Zero(n, mr);
  ws.W = Eigen::MatrixXd::Zero(mr, mr);
  ws.b = ws.P = Eigen::VectorXd::Zero(mr);
  ws.equality.L = Eigen::MatrixXd::Zero(mr, mr);
  ws.equality.scale = ws.equality.U = ws.equality.correction = Eigen::VectorXd::Zero(mr);
  ws.equality.x = Eigen::VectorXd::Zero(2 * mr);
  ws.equality.rows.assign(mr, 0);
  ws.equality.perm.assign(2 * mr, 0);
  ws.equality.factor_rows = 0;
  ws.blocks.reserve(mr);
  ws.stale_joint_row.assign(m.joints.size(), -1);
  ws.placements.resize(m.joints.size());
  placeGroundSides(m, ws);
  ws.stale_joints = 0;
  // Projection passes add up to kRingFacets facets per penetrating ring.
  ws.candidates.reserve(f.contact_slots + 2 * kRingFacets * m.clearance_joints.size());
  ws.deferred.reserve(f.contact_slots);
  ws.ring_hint.assign(2 * m.clearance_joints.size(), std::numeric_limits<double>::quiet_NaN());
  ws.check_hint = ws.ring_hint;
  ws.halving_hint = ws.ring_hint;
  initNarrowphaseCache(ws.nbodies, static_cast<int>(m.contacts.size()),
                       static_cast<int>(m.clearance_joints.size()), ws.narrow);
  ws.row_bodies.assign(mr, {kGround, kGround});
  ws.row_support.assign(mr, 0);
  ws.problem.reserve(mr);
  ws.rates.assign(m.actuators.size(), 0.0);
  ws.zero_rates.assign(m.actuators.size(), 0.0);
}

// Allowed velocity directions: all, or the x-y plane motions (3 per body); and
// the buffers of the reduced (basis-projected) solves.
void buildVelocityBasis(const Model& m, StepWorkspace& ws) {
  const int n = ws.n;
  const bool planar = ws.facts.planar;
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
}

// The bodies' blocks of M^-1 as StepWorkspace::BodyMassInverse, if they all
// have its form: exact zeros off the translation diagonal and between
// translation and rotation (what the mass matrix and its planar projection give).
void splitMassInverse(StepWorkspace& ws) {
  ws.body_mass_inverse.assign(ws.nbodies, StepWorkspace::BodyMassInverse{});
  ws.mass_inverse_by_body = true;
  for (int b = 0; b < ws.nbodies; ++b) {
    const auto blk = ws.mass_inverse.block<6, 6>(6 * b, 6 * b);
    StepWorkspace::BodyMassInverse& bi = ws.body_mass_inverse[b];
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) {
        const bool kept = (r == c && r < 3) || (r >= 3 && c >= 3);
        if (!kept && blk(r, c) != 0) ws.mass_inverse_by_body = false;
      }
    for (int k = 0; k < 3; ++k) bi.lin[k] = blk(k, k);
    bi.ang_diagonal = true;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        bi.ang[r][c] = blk(3 + r, 3 + c);
        if (r != c && bi.ang[r][c] != 0) bi.ang_diagonal = false;
      }
  }
}

// Constant mass matrix and its (planar-projected) inverse, which is also the
// iteration matrix's inverse until the stiff elements change it; and the blocks
// of the stiff groups' own iteration matrices.
void buildMassMatrix(const Model& m, StepWorkspace& ws) {
  for (int i = 0; i < ws.nbodies; ++i) {
    ws.A.block<3, 3>(6 * i, 6 * i) = m.bodies[i].mass * Mat3::Identity();
    ws.A.block<3, 3>(6 * i + 3, 6 * i + 3) = m.bodies[i].inertia;
  }
  if (!reducedInverse(ws.A, ws, ws.mass_inverse))
    throw std::runtime_error(m.source_file + ": mass matrix is not positive definite");
  ws.iteration_inverse = ws.mass_inverse;
  splitMassInverse(ws);
  ws.group_A.clear();
  ws.group_inverse.clear();
  ws.group_factor_inverse.clear();
  for (const std::vector<int>& g : ws.facts.stiff_groups) {
    const int k = 6 * static_cast<int>(g.size());
    ws.group_A.push_back(Eigen::MatrixXd::Identity(k, k));
    ws.group_inverse.push_back(Eigen::MatrixXd::Identity(k, k));
    ws.group_factor_inverse.push_back(Eigen::MatrixXd::Zero(k, k));
    if (static_cast<int>(ws.group_dofs.size()) < k) ws.group_dofs.resize(k);
  }
}

}  // namespace

void initStepWorkspace(const Model& m, StepWorkspace& ws) {
  ws.nbodies = static_cast<int>(m.bodies.size());
  ws.n = 6 * ws.nbodies;
  collectModelFacts(m, ws.facts);
  sizeStepBuffers(m, ws);
  buildVelocityBasis(m, ws);
  buildMassMatrix(m, ws);
}

namespace {

void zeroBlockRows(StepWorkspace& ws, int row, int size, int body_a, int body_b) {
  for (int k = row; k < row + size; ++k) {
    if (body_a != kGround) ws.G.block<1, 6>(k, 6 * body_a).setZero();
    if (body_b != kGround) ws.G.block<1, 6>(k, 6 * body_b).setZero();
  }
}

}  // namespace

void clearConstraintRows(StepWorkspace& ws) {
  // G is zero outside the registered blocks' rows and bodies (it starts zero and
  // every row is written at its block's bodies only), so only those are cleared,
  // and a joint's whose next gather writes them whole again (rows_written_whole:
  // the rows of every gather sit at the same places) only then, if it does not
  // (clearStaleJointRows).
  for (const ConstraintBlock& blk : ws.blocks) {
    if (blk.joint >= 0 && ws.facts.rows_written_whole[blk.joint]) {
      int& stale = ws.stale_joint_row[blk.joint];
      if (stale == blk.row) continue;
      if (stale >= 0) zeroBlockRows(ws, stale, blk.size, blk.body_a, blk.body_b);
      else ++ws.stale_joints;
      stale = blk.row;
      continue;
    }
    zeroBlockRows(ws, blk.row, blk.size, blk.body_a, blk.body_b);
  }
  ws.blocks.clear();
  ws.rows = 0;
  ws.rows_keyed = false;
}

void clearStaleJointRows(const Model& m, StepWorkspace& ws, int first_row) {
  if (ws.stale_joints == 0) return;
  for (size_t j = 0; j < ws.stale_joint_row.size(); ++j) {
    int& stale = ws.stale_joint_row[j];
    if (stale < 0) continue;
    if (stale != first_row + ws.facts.joint_row_base[j]) zeroBlockRows(ws, stale, 5, m.joints[j].body_a, m.joints[j].body_b);
    stale = -1;
  }
  ws.stale_joints = 0;
}

void keyRowsOnPoses(const State& s, StepWorkspace& ws) {
  if (!ws.facts.rows_follow_poses) return;
  for (int i = 0; i < ws.nbodies; ++i) {
    ws.rows_key[i].x = s.bodies[i].x;
    ws.rows_key[i].q = s.bodies[i].q;
  }
  ws.rows_keyed = true;
}

bool rowsMatchPoses(const State& s, const StepWorkspace& ws) {
  if (!ws.rows_keyed) return false;
  for (int i = 0; i < ws.nbodies; ++i)
    if (s.bodies[i].x != ws.rows_key[i].x || s.bodies[i].q.coeffs() != ws.rows_key[i].q.coeffs()) return false;
  return true;
}

void initStepOutputs(const Model& m, StepOutputs& out) {
  out.reports.reserve(3 * (m.contacts.size() * kMaxPointsPerPair +
                           m.clearance_joints.size() * kMaxClearancePoints) + 1);
  out.actuator_effort.assign(m.actuators.size(), 0.0);
  out.pair_fn.assign(m.contacts.size(), 0.0);
  out.pair_ft.assign(m.contacts.size(), 0.0);
  out.pair_ft_vec.assign(m.contacts.size(), Vec3::Zero());
  out.cj_fn.assign(m.clearance_joints.size(), 0.0);
  clearStepOutputs(out);
}

void clearStepOutputs(StepOutputs& out) {
  out.stats = StepStats();
  out.penetration_pending = false;
  out.reports.clear();
  std::fill(out.actuator_effort.begin(), out.actuator_effort.end(), 0.0);
  std::fill(out.pair_fn.begin(), out.pair_fn.end(), 0.0);
  std::fill(out.pair_ft.begin(), out.pair_ft.end(), 0.0);
  std::fill(out.pair_ft_vec.begin(), out.pair_ft_vec.end(), Vec3::Zero());
  std::fill(out.cj_fn.begin(), out.cj_fn.end(), 0.0);
}

State initialState(const Model& m, const StepWorkspace& ws) {
  State s;
  s.t = 0;
  s.bodies.resize(ws.nbodies);
  for (int i = 0; i < ws.nbodies; ++i) {
    const Body& b = m.bodies[i];
    BodyState& bs = s.bodies[i];
    bs.x = b.initial_pose.p;
    bs.q = b.initial_pose.q.normalized();
    bs.v = b.initial_velocity;
    bs.w = bs.q.conjugate() * b.initial_angular_velocity;
    if (ws.facts.planar) {  // keep only the in-plane part of the initial velocity
      bs.v.z() = 0;
      bs.w = bs.q.conjugate() * Vec3(0, 0, (bs.q * bs.w).z());
    }
  }
  s.commands.resize(m.actuators.size());
  for (size_t i = 0; i < m.actuators.size(); ++i) s.commands[i] = m.actuators[i].initial_command;
  s.prev_commands = s.commands;
  s.warm.assign(ws.facts.contact_slots, Vec3::Zero());
  s.warm_valid.assign(ws.facts.contact_slots, 0);
  s.warm_bilateral.assign(ws.facts.bilateral_rows, 0.0);
  s.ring_hint.assign(2 * m.clearance_joints.size(), std::numeric_limits<double>::quiet_NaN());
  s.joint_position.resize(m.joints.size());
  for (size_t j = 0; j < m.joints.size(); ++j) s.joint_position[j] = m.joints[j].initial_position;
  return s;
}

}  // namespace nscd
