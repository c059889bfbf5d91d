// The stages of a time step (Simulator::step calls them in this order), one file
// each, over the immutable Model, the State and the step's workspace
// (step_workspace.hpp). Internal to the engine.
#pragma once

#include "step_workspace.hpp"

namespace nscd {

// ---- set-up (step_workspace.cpp)
// Sizes every buffer for the model and computes the model's facts; M^-1.
// Throws std::runtime_error if the mass matrix is not positive definite.
void initStepWorkspace(const Model& m, StepWorkspace& ws);
// Sizes the outputs of a step for the model (all zero).
void initStepOutputs(const Model& m, StepOutputs& out);
// Clears the outputs of the last step (sizes kept).
void clearStepOutputs(StepOutputs& out);
// Drops the constraint blocks and zeroes their rows of G (the row writers rely
// on G being zero outside the registered blocks), but for the joints whose next
// full gather writes their rows whole at the same places
// (ModelFacts::rows_written_whole): those are left to that gather
// (clearStaleJointRows), and G is read only after one.
void clearConstraintRows(StepWorkspace& ws);
// At a full gather's start (appendBilateralRows, first_row: its first row): the
// rows clearConstraintRows left that the gather does not write again at the same
// places are zeroed; the others it overwrites.
void clearStaleJointRows(const Model& m, StepWorkspace& ws, int first_row);
// The rows now in ws kept as a memo of the state's poses, when the model's rows
// follow the poses (ModelFacts::rows_follow_poses); else nothing.
void keyRowsOnPoses(const State& s, StepWorkspace& ws);
// Whether ws holds the rows of the state's poses (keyed, not cleared since).
bool rowsMatchPoses(const State& s, const StepWorkspace& ws);
// The state at the initial poses and velocities of the model (before assembly).
State initialState(const Model& m, const StepWorkspace& ws);
// Assembly (assembly.cpp): positions projected onto the constraints, then the
// velocities onto the ideal joints' G v = 0. Throws std::runtime_error naming
// the scene if the positions cannot be assembled.
void assembleState(const Model& m, State& s, StepWorkspace& ws);
// Journal placement (journal_placement.cpp), before the assembly: moves the bodies
// so that every clearance joint with an initial offset has its journal there,
// axes kept parallel. Throws std::runtime_error naming the scene if it cannot.
void placeJournals(const Model& m, State& s);

// ---- 1. forces (forces.cpp): gravity, force actuators, springs and PD actuators
// at the state; with jacobians, their symmetrised derivatives K = dF/dq and C =
// dF/dv. Actuator efforts of force and PD actuators go to out.
void computeForces(const Model& m, const State& s, StepWorkspace& ws, StepOutputs& out,
                   bool with_jacobians);
// Force in a spring at the state (tension, or torque on the child for torsion): its
// scalar, which its loads (if any) are multiples of.
double springForceAt(const Model& m, const State& s, int spring);
// Its law's stretch at the state: length - rest length, or angle - rest angle.
double springStretchAt(const Model& m, const State& s, int spring);
// Power of its forces on its bodies at the state (W), its body-fixed loads' if any.
double springLoadPowerAt(const Model& m, const State& s, int spring);
Vec3 bodyPointWorld(const State& s, int body, const Vec3& local);

// ---- 1b. iteration matrix (iteration_matrix.cpp): rhs = h F (+ h^2 theta K v_k)
// and Ŵ = (M - h theta C - h^2 theta^2 K)^-1 when the model has stiff elements
// (else Ŵ = M^-1). Needs ws.vk.
void buildIterationMatrix(const Model& m, double h, StepWorkspace& ws, StepStats& st);
// y += Ŵ x, from Ŵ's blocks within the stiff groups (it couples no others).
void addIterationInverseTimes(const StepWorkspace& ws, const Eigen::VectorXd& x,
                              Eigen::VectorXd& y);
// B (B^T A B)^-1 B^T (B: the allowed velocity directions). False if not SPD.
bool reducedInverse(const Eigen::MatrixXd& A, StepWorkspace& ws, Eigen::MatrixXd& out);

// ---- 1c. free velocity (free_velocity.cpp): v_free = v_k + Ŵ rhs, with the
// gyroscopic torques as backward-Euler impulses.
void computeFreeVelocity(const Model& m, double h, StepWorkspace& ws);

// ---- 2a. bilateral rows (joint_rows.cpp, one file per joint kind): ideal joints
// and prescribed actuators, with their position errors and rheonomic targets.
// rates[i]: commanded rate of actuator i (prescribed).
// jacobian false: the rows' errors only where a joint kind can skip its G rows
// (revolute joints: their G rows stay as clearConstraintRows left them, zero or
// the last full gather's), for a check of the violation whose rows are not used
// (G is not read before the next full gather).
void appendBilateralRows(const Model& m, const State& s, const std::vector<double>& rates,
                         StepWorkspace& ws, bool jacobian = true);
// The G rows a gather of the errors alone (jacobian false) left out, for the same
// state, from the placements it kept: then ws holds what a full gather gives.
void completeBilateralRows(const Model& m, const State& s, StepWorkspace& ws);
// ws.ground_sides: the ground side of every joint on the ground, placed once.
void placeGroundSides(const Model& m, StepWorkspace& ws);
// Continuous joint coordinate at the state (State::joint_position as the reference).
double jointPosition(const Model& m, const State& s, int joint);
double jointVelocity(const Model& m, const State& s, int joint);
// Follows every joint's continuous coordinate to the state's positions (after a
// step; at assembly from 0).
void trackJointPositions(const Model& m, State& s);

// ---- 2b. contact candidates (contact_candidates.cpp)
// Largest turn of a contact normal between q_k and the predicted configuration
// for which the predicted rows are used (rad).
constexpr double kMaxPredictedTurn = 0.1;
// Narrowphase: every contact point of the shape pairs (contact_pair.cpp) and
// clearance joints (clearance_joint.cpp) within reach of the step (or of the
// projection's correction, extra_margin), into ws.candidates. ring_hint (2 per
// clearance joint) starts the ring searches and is updated. In Step mode with
// contact_prediction > 0, a candidate's rows come from the same feature at
// ws.predicted (q_k + h v_k, Siconos's convention) when its normal there turns by
// less than kMaxPredictedTurn; gaps and activation stay those of q_k.
void findContactCandidates(const Model& m, const State& s, double h, CandidateMode mode,
                           double extra_margin, double* ring_hint, StepWorkspace& ws);
// Activation and rows: in Step mode, a candidate whose gap closes within the step
// (predicted from v_k, or from v_free) gets its rows, the others wait in
// ws.deferred; in the projection modes every candidate gets a normal row, whose
// Jacobian row in G is left for the caller to write (writeJacobianRows).
void activateContacts(const Model& m, const State& s, double h, CandidateMode mode,
                      StepWorkspace& ws);
// Deferred candidates that close under the solved velocity ws.vnew (g + h
// u_N(v_new) <= 0) get their rows. Returns how many.
int activateLateContacts(const Model& m, const State& s, double h, StepWorkspace& ws);
// Writes the Jacobian rows of block `blk` (geometry blk.contact.row_cp) into G;
// `s` is the state that geometry belongs to.
void writeJacobianRows(const State& s, const ConstraintBlock& blk, Eigen::MatrixXd& G);

// ---- 3. Delassus operator (delassus_operator.cpp): Y = Ŵ G^T and W = G Y for
// rows [from, r), from the two bodies of each row; rows below `from` are kept
// (rows appended to a problem already assembled). block_diagonal: Ŵ couples no two
// bodies, so each row is mapped by its bodies' 6 x 6 blocks alone.
void assembleDelassus(const Eigen::MatrixXd& iteration_inverse, bool block_diagonal,
                      StepWorkspace& ws, int from, int r);
// The same W's lower triangle alone (the upper is left as it was) and Y, for
// rows [0, r), where Ŵ = M^-1 in the form bodies have (!facts.stiff,
// mass_inverse_by_body) and nbodies <= 64: the direct equality step's operator,
// bit for bit assembleDelassus's there, from each pair of blocks that share a body.
void assembleEqualityDelassus(StepWorkspace& ws, int r);

// ---- 4a. the friction-contact problem (friction_contact_problem.cpp): b = G v_free
// minus the bilateral targets plus the Newton impact shift e U_N,k, the problem
// blocks, and the impulses of rows from `kept` on warm-started from the State.
void buildFrictionContactProblem(const Model& m, const State& s, double h, int kept,
                                 StepWorkspace& ws, StepStats& st);
// Takes the Newton impact shift back out of b: the plastic problem.
void removeRestitution(StepWorkspace& ws);
// b = G v_free of every row over its bodies' columns (a finite v_free), with a
// bilateral row's target and an ideal joint's workless average (joint_average > 0).
void rowFreeVelocities(double joint_average, StepWorkspace& ws);

// ---- 3-4 for bilateral rows alone (equality_step.cpp): with no contact
// sources every row is an ideal joint's or a prescribed motion's, and the
// problem is W P = -b: W (rows [0, ws.rows)), b and one LDLᵀ solve, its factor
// kept in ws.equality; the impulses applied and st filled as the general path
// does (SolverStage::Equalities, st.direct_equality_solves counted). False,
// nothing in st changed, where that answer is not the solver's (a non-finite
// entry, a residual above the tolerance): the general path then takes the step.
bool solveEqualityStep(const Model& m, StepWorkspace& ws, StepStats& st);
// P = -W⁺ rhs (r rows; zero and dependent rows 0) from ws.equality's factor.
void solveWithEqualityFactor(StepWorkspace& ws, int r, const double* rhs, double* P);

// ---- 4b. solve (contact_solve.cpp): the solver's options for a step, and
// v+ = v_free + Ŵ G^T P into ws.vnew.
SolverOptions solverOptions(const Settings& set);
void applyImpulses(StepWorkspace& ws);

// ---- 4c. the solve and its rescues (rescue_policy.cpp): the problem of rows
// [0, ws.rows) solved and its impulses applied, then the rescues of StepRescue
// in their order (those after Halving only if !may_halve), each counted in st.
// Each solve is shown to observe.fn, if set (ProblemView::resolve names a
// rescue's). Returns the report of the answer that stands.
struct ResolveObserver {
  const ProblemObserver* fn = nullptr;
  double t = 0;
  int round = 0, halvings = 0, substep = 0;
};
SolverReport solveWithRescues(const Model& m, StepWorkspace& ws, const SolverOptions& options, bool may_halve,
                              const ResolveObserver& observe, StepStats& st);

// ---- 4d. store (impulse_reports.cpp): the impulses as the next step's warm start
// (in the State), the efforts of prescribed motions, one report per contact point
// and the sums per named contact and clearance joint.
void storeImpulses(const Model& m, double h, State& s, const StepWorkspace& ws,
                   StepOutputs& out);

// ---- 5. integrate (time_integration.cpp): x, q from theta v_{k+1} + (1 - theta)
// v_k, v = v_{k+1}, t += h; the commands become the previous commands.
void advanceState(const Model& m, double h, const StepWorkspace& ws, State& s);
void integratePositions(State& s, const Eigen::VectorXd& vk, const Eigen::VectorXd& vnew,
                        double h, double theta);
// out = s with positions advanced by `ahead` * v (velocities kept). out.bodies
// must have s's size (no allocation).
void predictState(const State& s, double ahead, State& out);
void applyDisplacement(State& s, const Eigen::VectorXd& dq);
void stateVelocities(const State& s, Eigen::VectorXd& v);
void setStateVelocities(State& s, const Eigen::VectorXd& v);

// ---- 6. projection (projection.cpp): positions onto {g >= 0, h = 0} until the
// violation is below tol or max_passes; returns the passes, writes the remaining
// violation. Updates s (positions and ring hints). reuse: the first pass may
// take the velocity stage's operator (velocityFactorReusable says when).
// stall_passes > 0: also stops when that many passes in a row have not halved
// the violation (the assembly: a pose no pass can close gives up early).
int projectPositions(const Model& m, State& s, StepWorkspace& ws, int max_passes, double tol,
                     double& violation, StepStats& st, bool reuse = false, int stall_passes = 0);
// After the velocity stage, before anything else assembles or solves: whether
// the first projection pass may take its Y = M^-1 G_k^T and the solver's LDLᵀ
// factor of its W_k = G_k M^-1 G_k^T (q_k) in place of its own at q_{k+1}. A
// chord Newton step: the same rows, but for the configuration they are
// evaluated at; its correction lowers the violation by the rows' turn over the
// step (h |w|) where Newton's squares it, and the check after it measures the
// exact violation (a pass more where it falls short). True for a model of ideal
// joints alone (no contact rows to come and go) without stiff elements (Ŵ =
// M^-1) whose bodies turn by less than 0.02 rad in the step.
bool velocityFactorReusable(double h, const StepWorkspace& ws);
// Largest penetration of the unilateral contacts (positive length) of the state;
// the largest bilateral position error goes to *bilateral if given. Uses a copy
// of the state's ring hints: the state is not changed.
double measureViolation(const Model& m, const State& s, StepWorkspace& ws,
                        double* bilateral = nullptr);
// The position-level problem of the rows a check gathered at s: its blocks
// (ws.problem), the contact rows' Jacobians written into ws.G (the check gathers
// their gaps only) and b = the rows' errors and gaps. For the projection's
// passes and the energy take-back's impact (which sets b again).
void positionProblem(const State& s, StepWorkspace& ws);

// ---- 7. energy bookkeeping (energy_bookkeeping.cpp)
EnergyReport potentialEnergyOf(const Model& m, const State& s);
double kineticEnergyOf(const Model& m, const State& s);
// Kinetic energy of a generalized velocity (linear world, angular body frame).
double kineticEnergyOf(const Model& m, const Eigen::VectorXd& v);
// Kinetic plus potential energy of the state.
double totalEnergyOf(const Model& m, const State& s);
// The energy at a step's start plus the inputs' work in the step, evaluated only
// when the take-back asks for it: the start state's (totalEnergyOf), or, the
// state gone on, the kinetic energy of its velocities as stateVelocities wrote
// them (a fixed step's ws.vk) plus its potential energy and the inputs' work.
struct StepStartEnergy {
  const State* state = nullptr;
  const Eigen::VectorXd* velocities = nullptr;
  double potential = 0, input_work = 0;
  double value(const Model& m) const;
};
// Potential energy the projection added beyond potential_before (the potential
// before it plus the inputs' work in the step), as far as the step as a whole
// gained energy beyond the start's (StepStartEnergy), taken back from the kinetic
// energy of the bodies whose motion is not prescribed: where the projection's last
// check has contact rows, first by a plastic impact on them (contacts approaching
// faster than their gap closes in a step of h); with ideal joints alone, first
// from the velocity against the projection's correction (from
// ws.unprojected_bodies); the rest by one common factor. Writes the problem
// buffers (W, Y, b, P) and ws.dq. Returns what was taken (J).
double takeBackProjectionEnergy(const Model& m, double h, StepWorkspace& ws, double potential_before,
                                const StepStartEnergy& start, State& s);
// Work the inputs did in the step just solved (J, >= 0): prescribed motions
// (effort x commanded displacement), position servos (effort x joint motion) and
// springs applied as body-fixed loads (their power at the step's end x h).
double inputWorkOfStep(const Model& m, double h, const StepWorkspace& ws, const StepOutputs& out, const State& s);

// ---- 8. step halving (step_halving.cpp): a step left unsolved is taken again
// as substeps (Simulator::step); their stats and outputs are gathered here.
// The unsolved attempt: its work goes into `total`, the accumulated outputs start at 0.
void startHalvedStep(const StepStats& attempt, StepStats& total, StepOutputs& acc);
// An attempt a halving drops: its work (iterations, solves) counted in `total`.
void addDroppedAttempt(const StepStats& attempt, StepStats& total);
// A substep kept, of length dt / 2^level: its stats into `total`, its
// actuator efforts and contact forces (impulse / its length) into `acc`, as
// their share of the step's impulse.
void addSubstep(const StepStats& sub, int level, const StepOutputs& out, StepStats& total,
                StepOutputs& acc);
// The step's outputs: those of the last substep (contact points, penetration),
// with the stats of `total` and the forces and efforts averaged over the step.
void finishHalvedStep(const StepStats& total, const StepOutputs& acc, StepOutputs& out);

}  // namespace nscd
