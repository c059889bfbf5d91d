// The data of a time step, internal to the engine: the preallocated buffers the
// stages share (StepWorkspace), what a step reports (StepOutputs), and the
// constraint rows they pass along. Dynamic state lives in State (simulator.hpp);
// nothing here carries information from one step to the next, except outputs
// and two memos keyed on the poses: the narrowphase's (narrowphase_cache.hpp)
// and, in a model of ideal joints alone, the rows of the last gather.
// The stage functions are declared in step_stages.hpp.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "nscd_sim/clearance_geometry.hpp"
#include "nscd_sim/contact_geometry.hpp"
#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/simulator.hpp"
#include "geometry/narrowphase_cache.hpp"

namespace nscd {

// A unilateral contact point that may enter the step's problem: where it is, on
// which bodies, and where its rows are built.
struct ContactCandidate {
  ContactPoint cp;       // world geometry at q_k; normal from B to A
  // The geometry the rows are built from: cp, or the same feature at the
  // predicted configuration ws.predicted (row_ahead); see findContactCandidates.
  ContactPoint row_cp;
  bool row_ahead = false;
  int body_a = kGround, body_b = kGround;
  double mu = 0, e = 0;
  int source = -1;       // contact pair or clearance joint index
  bool clearance = false;
  int slot = -1;         // warm-start slot (-1: projection facets, no warm start)
  // A contact the activation deferred (activateContacts), if a solve's answer then
  // closes it (activateLateContacts): its gap at q_k (> 0), which it may close in
  // the step (friction_contact_problem.cpp). 0 for the others.
  double late_slack = 0;
};

// One block of constraint rows: a contact point, or the bilateral rows of one
// ideal joint or prescribed motion.
struct ConstraintBlock {
  BlockKind kind = BlockKind::Frictional;
  int row = 0;    // first row in G
  int size = 3;
  int body_a = kGround, body_b = kGround;
  // Unilateral contacts: the candidate and its tangent directions.
  ContactCandidate contact;
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
  // Bilateral rows: target velocity (rheonomic) and position error per row.
  double target[6] = {0, 0, 0, 0, 0, 0};
  double error[6] = {0, 0, 0, 0, 0, 0};
  int joint = -1;           // ideal joint index, or -1
  int actuator = -1;        // prescribed actuator index, or -1
  // What the rows' writer knows of each row's linear part (the first three of its
  // six columns on each of its bodies): linear_known, and per row its axis k (0-2:
  // zero but for entry k, a finite one; one row per axis at most) or kLinearZero
  // (all three zero). The
  // Delassus operator skips those exact zeros' products (delassus_operator.cpp).
  bool linear_known = false;
  signed char linear_axis[6] = {0, 0, 0, 0, 0, 0};
};
constexpr signed char kLinearZero = 3;

// A joint's placement (joint_rows.hpp's JointPlacement, its bodies' states aside),
// kept by a gather of the rows' errors alone for completeBilateralRows.
struct PlacementMemo {
  Vec3 pa, pb, axis_a, dp;
  Vec3 frame[3];
};

// Which contact candidates a geometry pass gathers.
enum class CandidateMode {
  Step,        // the velocity step: frictional rows, activation, predicted rows
  Projection,  // position projection: normal rows, penetrating rings get facets
  Measure,     // violation queries: normal rows only
};

// Facts of the model the step needs, computed once when the simulator is made.
struct ModelFacts {
  int contact_slots = 0;                // kMaxPointsPerPair per pair, kMaxClearancePoints per joint
  int contact_slot_base_clearance = 0;  // first slot of the clearance joints
  std::vector<int> joint_row_base;      // first bilateral warm slot of each ideal joint
  std::vector<int> actuator_row_base;   // of each prescribed actuator
  int bilateral_rows = 0;
  bool stiff = false;    // springs or PD actuators: an iteration matrix, coupled bodies
  // The bodies that springs and PD actuators join (connected components, ground
  // left out), each ascending: the iteration matrix is block-diagonal over them
  // (every other body keeps its M^-1 block).
  std::vector<std::vector<int>> stiff_groups;
  // Per body: the bodies Ŵ couples it with, itself included, ascending (its
  // stiff group, or itself alone).
  std::vector<std::vector<int>> coupled;
  std::vector<std::uint64_t> coupled_mask;  // the same as bits (models of up to 64 bodies)
  std::vector<std::array<double, 2>> pair_reach;  // per contact pair: shapeReach of a and b
  bool planar = false;   // x-y plane motions only
  // Per body: its motion is prescribed (an input), so energy bookkeeping leaves its
  // velocity alone.
  std::vector<char> prescribed_body;
  // Per joint: every full gather writes its rows whole on its bodies (a revolute
  // joint between two bodies), at facts.joint_row_base from the gather's first row.
  std::vector<char> rows_written_whole;
  // Ideal joints alone (no contact pairs, clearance joints or prescribed
  // motions): the rows of a gather depend on the bodies' poses alone.
  bool rows_follow_poses = false;
};

// The LDLᵀ factor of a step's bilateral W (equality_step.cpp): the rows not
// zero (rows[0 .. ne)), W on them scaled to a unit diagonal by `scale`
// (1 / sqrt(W_ii)) and factored in the pivoting order `perm` (and its scratch);
// factor_rows: the step's rows while the factor stands (the projection's first
// pass may take it), else 0.
struct EqualityFactor {
  Eigen::MatrixXd L;
  Eigen::VectorXd scale, x, U, correction;
  std::vector<int> rows, perm;
  int ne = 0;
  int factor_rows = 0;
};

class StepWorkspace {
 public:
  ModelFacts facts;
  int nbodies = 0;
  int n = 0;         // 6 * nbodies
  int max_rows = 0;  // bilateral rows + 3 per contact slot

  // Forces and their (symmetrised) derivatives
  Eigen::VectorXd F;       // generalized force at t_k
  Eigen::MatrixXd K;       // dF/dq (through the exponential map), symmetric part
  Eigen::MatrixXd C;       // dF/dv, symmetric part
  // (K_full - K_full^T)/2 v_k of the springs with body-fixed loads (forces.cpp): the
  // part of the force's change over the step that K, symmetric, leaves out; the
  // step takes it explicitly (rhs += h^2 theta K_skew_v, iteration_matrix.cpp).
  Eigen::VectorXd K_skew_v;
  Eigen::MatrixXd A;       // iteration matrix M - h theta C - h^2 theta^2 K
  Eigen::MatrixXd iteration_inverse;  // Ŵ = A^-1 (planar-projected)
  Eigen::MatrixXd mass_inverse;       // M^-1 (planar-projected): Ŵ without stiff elements
  // Each body's 6 x 6 block of mass_inverse in the form bodies have (the
  // translation part diagonal, no translation-rotation terms), when every body's
  // block has it (mass_inverse_by_body): Y = M^-1 G^T from 12 products a piece
  // instead of 36 (delassus_operator.cpp).
  struct BodyMassInverse {
    double lin[3];
    double ang[3][3];
    bool ang_diagonal = false;  // ang's off-diagonal entries exact zeros (principal axes)
  };
  std::vector<BodyMassInverse> body_mass_inverse;
  bool mass_inverse_by_body = false;
  Eigen::MatrixXd basis;   // n x nred, allowed velocity directions (planar mode)
  Eigen::MatrixXd red;     // nred x nred scratch
  Eigen::MatrixXd AB, BT;  // planar scratch: A B (n x nred), B^T (nred x n)
  Eigen::LLT<Eigen::MatrixXd> llt;
  // Per stiff group (facts.stiff_groups): its block of A (then its Cholesky factor),
  // the factor's inverse, the block's inverse.
  std::vector<Eigen::MatrixXd> group_A, group_factor_inverse, group_inverse;
  std::vector<int> group_dofs;  // scratch: a group's coupled DOFs (iteration_matrix.cpp)
  Eigen::VectorXd rhs, vk, vfree, vnew;
  Eigen::VectorXd gyro_impulse;  // free velocity: backward-Euler gyroscopic impulses
  Eigen::VectorXd dq;            // projection: the displacement of a pass
  std::vector<BodyState> saved_bodies;  // projection: state before a pass (backtracking)
  std::vector<BodyState> unprojected_bodies;  // projection: state before its first pass (energy take-back)
  std::vector<Vec3> projection_turn;          // energy take-back: each body's turn in the projection
  Eigen::VectorXd saved_dq;             // projection: the unsolved pass's correction
  // Projection: its last pass took the velocity stage's factor (velocityFactorReusable).
  bool projection_reused_factor = false;
  Eigen::VectorXd retry_P, retry_b;     // impact safeguards: the answer a plastic retry may replace
  State predicted;  // q_k advanced by ahead * v_k: where the contact rows are evaluated
  std::vector<Vec3> omega_world;  // activation: each body's q * w (world angular velocity)
  std::vector<double> rates, zero_rates;  // prescribed actuators: commanded rates

  // Contact candidates of the current geometry pass, and those of the step left
  // out of its problem (activateLateContacts checks them against the answer).
  std::vector<ContactCandidate> candidates;
  std::vector<ContactCandidate> deferred;
  std::vector<double> ring_hint;  // ring angles the pass starts from (2 per clearance joint)
  std::vector<double> check_hint;  // projection: the ring hints before its check
  std::vector<double> halving_hint;  // a step that may be halved: the ring hints before its search

  // Constraint rows
  std::vector<ConstraintBlock> blocks;
  // Per joint (rows_written_whole): the first row of its rows that a clear left in
  // G (the next full gather writes them again, clearStaleJointRows), or -1.
  std::vector<int> stale_joint_row;
  int stale_joints = 0;
  std::vector<PlacementMemo> placements;  // per joint: at the last gather of the errors alone
  // Per joint whose body A is the ground: that side's placement (pa, axis_a, frame),
  // the same at every state (placeGroundSides).
  std::vector<PlacementMemo> ground_sides;
  std::vector<std::array<int, 2>> row_bodies;  // per row: the (at most) two bodies it touches
  std::vector<std::uint64_t> row_support;      // per row: bodies where its column of Y may be nonzero
  std::vector<ProblemBlock> problem;
  Eigen::MatrixXd G;       // max_rows x n
  Eigen::MatrixXd Y;       // n x max_rows: Ŵ G^T
  Eigen::MatrixXd W;       // max_rows x max_rows
  Eigen::VectorXd b, P;
  Eigen::VectorXd P_start;  // the warm start, kept only for a ProblemObserver
  FrictionContactSolver solver;
  EqualityFactor equality;  // a step of bilateral rows alone: its direct solve
  int rows = 0;
  // The rows above as a memo of the poses they were gathered at (keyRowsOnPoses;
  // models whose rows follow the poses): the projection's last check is the next
  // step's velocity rows. Dropped with the rows (clearConstraintRows).
  std::vector<BodyState> rows_key;
  bool rows_keyed = false;

  // The shape pairs' points of the projection's last pass, for the next step's
  // (keyed on the poses: a memo, not state).
  NarrowphaseCache narrow;
  ContactPoint points[kMaxClearancePoints];
  ContactPoint points_ahead[kMaxClearancePoints];  // the same pair at ws.predicted
};

// What the last step reports; cleared by reset() and setState().
struct StepOutputs {
  StepStats stats;
  bool penetration_pending = false;  // stats.max_penetration still to measure (no projection)
  std::vector<ContactReport> reports;
  std::vector<double> actuator_effort;
  std::vector<double> pair_fn, pair_ft;  // per contact pair
  std::vector<Vec3> pair_ft_vec;         // summed tangential force per contact pair
  std::vector<double> cj_fn;             // per clearance joint
};

// Contact pairs or clearance joints: contact rows can join a problem (else
// every problem of the model is its ideal joints' and prescribed motions' rows).
inline bool hasContactSources(const StepWorkspace& ws) { return ws.facts.contact_slots > 0; }

// to = from, ring hints of the same size (no allocation) copied in place: none to
// copy without clearance joints, where the vector's out-of-line assignment was
// most of a joints-only step's copies.
inline void copyRingHints(const std::vector<double>& from, std::vector<double>& to) {
  if (from.size() != to.size()) {
    to = from;
    return;
  }
  std::copy(from.begin(), from.end(), to.begin());
}

// The state of a body, or of ground (identity pose, at rest) for kGround.
inline const BodyState& bodyOrGround(const State& s, int body) {
  static const BodyState ground{};
  return body == kGround ? ground : s.bodies[body];
}

}  // namespace nscd
