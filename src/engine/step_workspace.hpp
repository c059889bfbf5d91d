// Preallocated buffers shared by the stages of a time step, and the stage
// functions themselves (one .cpp each). Internal to the engine.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "nscd_sim/clearance_geometry.hpp"
#include "nscd_sim/contact_geometry.hpp"
#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd {

// One block of constraint rows (a contact point or a group of bilateral rows).
struct ConstraintBlock {
  BlockKind kind = BlockKind::Frictional;
  int row = 0;    // first row in G
  int size = 3;
  int body_a = kGround, body_b = kGround;
  double mu = 0, e = 0;
  // Unilateral contacts
  ContactPoint cp;          // world geometry at q_k; normal from B to A
  // The geometry the rows are built from: cp, or the same feature at the
  // predicted configuration ws.predicted (row_ahead); see appendContactBlocks.
  ContactPoint row_cp;
  bool row_ahead = false;
  Vec3 t1 = Vec3::UnitX(), t2 = Vec3::UnitY();
  int source = -1;          // contact pair or clearance joint index
  bool clearance = false;
  int slot = -1;            // warm-start slot
  // Bilateral rows: target velocity (rheonomic) and position error per row
  double target[6] = {0, 0, 0, 0, 0, 0};
  double error[6] = {0, 0, 0, 0, 0, 0};
  int joint = -1;           // ideal joint index, or -1
  int actuator = -1;        // prescribed actuator index, or -1
};

// A contact candidate left out of this step's problem (its gap does not close
// under v_k or v_free); activateLateContacts checks it against the answer.
struct DeferredContact {
  ContactPoint cp;
  ContactPoint row_cp;  // as in ConstraintBlock
  bool row_ahead = false;
  int body_a = kGround, body_b = kGround;
  double mu = 0, e = 0;
  int source = -1;
  bool clearance = false;
  int slot = -1;
};

class StepWorkspace {
 public:
  int nbodies = 0;
  int n = 0;        // 6 * nbodies
  int max_rows = 0;

  // Forces and their (symmetrised) derivatives
  Eigen::VectorXd F;       // generalized force at t_k
  Eigen::MatrixXd K;       // dF/dq (through the exponential map), symmetric part
  Eigen::MatrixXd C;       // dF/dv, symmetric part
  Eigen::MatrixXd A;       // iteration matrix
  Eigen::MatrixXd Minv;    // Ŵ: inverse of the iteration matrix (planar-projected)
  Eigen::MatrixXd Mproj;   // M^-1 (planar-projected), for the position projection
  Eigen::MatrixXd basis;   // n x nred, allowed velocity directions (planar mode)
  Eigen::MatrixXd red;     // nred x nred scratch
  Eigen::MatrixXd AB, BT;  // planar scratch: A B (n x nred), B^T (nred x n)
  bool planar = false;
  Eigen::LLT<Eigen::MatrixXd> llt;
  Eigen::VectorXd rhs, vk, vfree, vnew, dv;
  std::vector<BodyState> saved_bodies;  // projection: state before a pass (backtracking)
  State predicted;  // q_k advanced by ahead * v_k: where the contact rows are evaluated
  bool ring_facets = false;  // projection: penetrating rings also get tangent facets
  std::vector<double> actuator_effort;
  std::vector<double> rates, zero_rates;  // prescribed actuators: commanded rates
  std::vector<double> spring_force;

  // Constraint rows
  std::vector<ConstraintBlock> blocks;
  std::vector<DeferredContact> deferred;  // capacity: one per contact slot
  std::vector<std::array<int, 2>> row_bodies;  // per row: the (at most) two bodies it touches
  std::vector<ProblemBlock> problem;
  Eigen::MatrixXd G;       // max_rows x n
  Eigen::MatrixXd Y;       // n x max_rows: Ŵ G^T
  Eigen::MatrixXd W;       // max_rows x max_rows
  Eigen::VectorXd b, P;
  FrictionContactSolver solver;
  int rows = 0;

  // Warm starts: 3 impulses per slot, and whether the slot was active last step
  std::vector<Eigen::Vector3d> warm;
  std::vector<char> warm_valid;
  std::vector<double> warm_bilateral;  // per bilateral row slot
  int contact_slot_base_clearance = 0;
  std::vector<int> joint_row_base;     // first bilateral warm slot of each joint
  std::vector<int> actuator_row_base;  // of each prescribed actuator
  std::vector<double> phi_hint;        // 2 per clearance joint
  std::vector<double> phi_saved;       // copy kept across const queries

  // Reports of the last step
  std::vector<ContactReport> reports;
  StepStats stats;
  bool penetration_pending = false;  // stats.max_penetration still to measure (no projection)
  std::vector<double> pair_gap, pair_fn, pair_ft;          // per contact pair
  std::vector<double> cj_fn;                               // per clearance joint

  ContactPoint points[kMaxClearancePoints];
  ContactPoint points_ahead[kMaxClearancePoints];  // the same pair at ws.predicted
};

// The state of a body, or of ground (identity pose, at rest) for kGround.
inline const BodyState& bodyOrGround(const State& s, int body) {
  static const BodyState ground{};
  return body == kGround ? ground : s.bodies[body];
}

// ---- stages (each in its own file) ----

// forces.cpp: gyroscopic impulses added to ws.vfree (backward Euler per body).
void addGyroscopicImpulses(const Model& m, double h, StepWorkspace& ws);
// forces.cpp: generalized forces at the state; with jacobians, K and C too.
void computeForces(const Model& m, const State& s, const std::vector<double>& commands,
                   StepWorkspace& ws, bool with_jacobians);
double jointPosition(const Model& m, const State& s, int joint);
// Force in a spring at the state (tension, or torque on the child for torsion).
double springForceAt(const Model& m, const State& s, int spring);
double jointVelocity(const Model& m, const State& s, int joint);
Vec3 bodyPointWorld(const State& s, int body, const Vec3& local);

// joint_constraints.cpp: bilateral rows of ideal joints and prescribed actuators.
// rate[i] = commanded rate of actuator i (prescribed), command[i] its value.
void appendBilateralBlocks(const Model& m, const State& s, const std::vector<double>& commands,
                           const std::vector<double>& rates, StepWorkspace& ws);

// contact_candidates.cpp: unilateral contact blocks whose gap is below the margin
// computed from the velocities; normal_only gives 1-row blocks (projection).
// Largest turn of a contact normal between q_k and the predicted configuration
// for which the predicted rows are used (rad).
constexpr double kMaxPredictedTurn = 0.1;
// With `predict`, the rows of a contact are built from the same feature at
// ws.predicted (q_k + h v_k, Siconos's convention) when its normal there turns
// by less than kMaxPredictedTurn from the one at q_k; gaps and activation stay
// those of q_k.
void appendContactBlocks(const Model& m, const State& s, double h, bool normal_only,
                         double extra_margin, bool predict, StepWorkspace& ws);
// Candidates of this step left out by appendContactBlocks that close under the
// solved velocity ws.vnew (g + h u_N(v_new) <= 0): appended as new blocks.
// Returns how many.
int activateLateContacts(const Model& m, const State& s, double h, StepWorkspace& ws);
// Writes the Jacobian rows of block `blk` (geometry blk.row_cp) into G; `s` is
// the state that geometry belongs to.
void writeJacobianRows(const State& s, const ConstraintBlock& blk, Eigen::MatrixXd& G);
// delassus_operator.cpp: Y = Minv G^T and W = G Y for rows [0, r), from the two
// bodies of each row. Columns of Y and rows/columns of W below `from` are kept as
// they are (rows appended to a problem already assembled).
// block_diagonal: Minv couples no two bodies (no stiff force element), so each row
// is mapped by its bodies' 6 x 6 blocks alone.
void assembleDelassus(const Eigen::MatrixXd& Minv, bool block_diagonal, StepWorkspace& ws,
                      int from, int r);

// projection.cpp: combined projection of positions onto the constraints.
// Returns the number of passes; writes the remaining violation.
int projectPositions(const Model& m, State& s, const std::vector<double>& commands,
                     StepWorkspace& ws, int max_passes, double tol, double& violation);

// time_integration.cpp: x_{k+1}, q_{k+1} from v_k, v_{k+1}.
void integratePositions(State& s, const Eigen::VectorXd& vk, const Eigen::VectorXd& vnew,
                        double h, double theta);
// out = s with positions advanced by `ahead` * v (velocities kept).
// out.bodies must have s's size (no allocation).
void predictState(const State& s, double ahead, State& out);
void applyDisplacement(State& s, const Eigen::VectorXd& dq);
void stateVelocities(const State& s, Eigen::VectorXd& v);
void setStateVelocities(State& s, const Eigen::VectorXd& v);

// Largest penetration of the unilateral contacts (positive length) of the state;
// the largest bilateral position error goes to *bilateral if given.
double measureViolation(const Model& m, const State& s, const std::vector<double>& commands,
                        StepWorkspace& ws, double* bilateral = nullptr);

}  // namespace nscd
