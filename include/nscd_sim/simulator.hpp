// The engine's front door: owns a Model, the State and the step workspace.
// nscd_run, the ROS node, the benchmarks and the tests all drive this class.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "nscd_sim/friction_contact_solver.hpp"
#include "nscd_sim/model.hpp"

namespace nscd {

struct BodyState {
  Vec3 x = Vec3::Zero();  // centre of mass, world
  Quat q = Quat::Identity();  // body frame -> world
  Vec3 v = Vec3::Zero();  // linear velocity, world
  Vec3 w = Vec3::Zero();  // angular velocity, BODY frame
};

// Everything that moves: with the Model, a State determines the rest of a run.
// Simulator::state() / setState() save, restore and branch runs (MuJoCo's
// mj_getState / mj_setState); a run continued from a restored State is
// bit-identical to the original.
struct State {
  double t = 0;
  std::vector<BodyState> bodies;
  // Actuator commands (Simulator::setCommand), and those of the previous step:
  // a prescribed motion's rate is their difference over the step.
  std::vector<double> commands;
  std::vector<double> prev_commands;
  // Warm starts: the impulse (normal, tangent 1, tangent 2) each contact slot had
  // in the last step, and whether it was active then; one impulse per bilateral row.
  // After an adaptive step, scaled to a quarter of step_next (the next step's
  // fine substep: adaptive_step.cpp).
  std::vector<Vec3> warm;
  std::vector<char> warm_valid;
  std::vector<double> warm_bilateral;
  // Per clearance joint, 2 ring angles (rad) where its rings last touched: the
  // start of the next ring-gap search (NaN: none yet).
  std::vector<double> ring_hint;
  // Per joint, its coordinate followed continuously from the start: a revolute
  // joint's angle is unwrapped across steps (it passes +-pi as it turns, 10 turns
  // are 20 pi), a prismatic joint's position. Drives, springs and reports use it.
  std::vector<double> joint_position;
  // Adaptive step control (Settings::step_control): the length the next step
  // tries (0: none yet, dt), and the error estimate of the last step kept (the
  // PI controller's memory; 0: none).
  double step_next = 0;
  double step_error = 0;
};

// One active contact point after a step (what the node and the CSV report).
struct ContactReport {
  int source = 0;        // index into Model::contacts, or clearance joint index
  bool clearance = false;  // true: source is a clearance joint
  int feature = 0;       // point within the pair / joint
  int body_a = kGround, body_b = kGround;
  Vec3 point = Vec3::Zero();   // world, on B's surface
  Vec3 normal = Vec3::UnitZ(); // world, from B towards A
  double gap = 0;        // at the end of the step, m
  double fn = 0;         // normal force (impulse / h), N
  Vec3 ft = Vec3::Zero();  // tangential force on A, world, N
  bool sliding = false;
};

struct StepStats {
  int iterations = 0;
  double residual = 0;
  bool converged = true;
  int active_contacts = 0;
  int rows = 0;
  int projection_passes = 0;
  int projection_least_distance = 0;  // passes whose problem Gauss-Seidel left unsolved, solved exactly
  double max_penetration = 0;  // largest (positive) penetration at the end of the step
  int late_contacts = 0;         // contacts added after the first solve (closed by its answer)
  // The rescues the step took (StepRescue, in the policy's order):
  bool cold_retry = false;        // the answer was not finite: solved again from P = 0 by NSGS alone
  bool plastic_fallback = false;  // restitution would have added energy: solved with e = 0
  // (halving: substeps > 1, below.) Left unsolved where the step may not be
  // halved (its smallest substep, or one after that stayed unsolved), the
  // problem was solved again from its answer with 10 times the budget before any
  // of the fallbacks below, and that answer kept (converged, or closer): the
  // physics unchanged.
  bool longer_solve = false;
  // Newton's impact law at coupled points left the problem unsolved and the plastic
  // law (e = 0, friction kept) solved it: the step is taken plastic. Its effect: the
  // kinetic energy after it minus that of the unsolved answer, relative to the
  // kinetic energy of v_free.
  bool plastic_retry = false;
  double plastic_retry_kinetic_change = 0;
  bool frictionless_fallback = false;  // unsolved (residual > 1e-3): taken frictionless, e = 0
  // Its effect on the step: the kinetic energy after the fallback minus that of the
  // unsolved answer it replaced, relative to the kinetic energy of v_free (0 if none).
  double fallback_kinetic_change = 0;
  bool energy_capped = false;   // still unsolved: impulses scaled so they add no kinetic energy
  // Potential energy the projection added beyond the inputs' work in the step,
  // taken back from the kinetic energy (J; see Simulator::step).
  double projection_energy_removed = 0;
  // The iteration matrix M - h theta C - h^2 theta^2 K was not positive definite:
  // the step used M^-1 (springs and PD actuators explicit).
  bool iteration_matrix_fallback = false;
  // The step's problem stayed unsolved, so it was taken again in halves
  // (Settings::max_step_halvings): the number of steps it was taken in (1: whole)
  // and the deepest halving (h / 2^halvings). The other fields then sum (counts,
  // iterations, the discarded attempts' included) or take the worst (residual,
  // converged, flags) over the substeps kept; penetration, contacts and rows are
  // those of the last.
  int substeps = 1;
  int halvings = 0;
  // Step control (Settings::step_control): the step's length, s. Adaptive steps
  // also report the attempts rejected before the step was kept, its error
  // estimate (the scaled difference of its coarse and fine paths, or the fine
  // path's own estimate where the coarse path was not taken; <= 1 but at the
  // floor dt_min; adaptive_step.hpp) and whether its answer is the Richardson
  // extrapolation (no contact opened, closed, stuck or slipped in it, and the
  // coarse path taken). The counts
  // and flags above then cover the fine path's substeps (iterations: every solve,
  // the coarse path's and the rejected attempts' included); substeps and halvings
  // those of the substep halved most.
  double h = 0;
  int rejected = 0;
  double error = 0;
  bool extrapolated = false;
  // How many of the step's friction-contact solves each stage of the solver's
  // schedule finished (SolverReport::stage; index: SolverStage), the rescues'
  // solves and those of the attempts a halving dropped included.
  std::array<int, kSolverStageCount> solves_by_stage{};
  // Of those, the solves of a problem of bilateral rows alone that the step
  // answered by its own LDLᵀ solve (no contact sources in the model), without
  // the friction-contact solver (counted in solves_by_stage as Equalities).
  int direct_equality_solves = 0;
};

// The rescues of a step whose friction-contact problem goes wrong, one ordered
// policy (src/engine/step/rescue_policy.cpp): each is tried in this order, and
// those after Halving only where the step may not be halved (its smallest
// substep, Settings::max_step_halvings, or one taken after such a substep stayed
// unsolved), because they change the physics or cost ten solves.
enum class StepRescue : std::uint8_t {
  ColdRetry,      // a non-finite answer: solved again from P = 0 by NSGS alone
  PlasticImpact,  // an impact whose restitution would add energy: solved with e = 0
  Halving,        // unsolved: the step taken again as two of h/2
  LongerSolve,    // unsolved where it may not be halved: solved again with 10 times the budget
  PlasticRetry,   // unsolved with restitution: solved with e = 0, kept if that converges
  Frictionless,   // unsolved and far off or adding energy: taken frictionless and plastic
  EnergyCap,      // still far off: the impulses scaled so they add no kinetic energy
};
constexpr int kStepRescueCount = 7;
// "cold_retry", "plastic_impact", "halving", "longer_solve", "plastic_retry",
// "frictionless", "energy_cap".
const char* stepRescueName(StepRescue rescue);
// Whether the step (or one of its substeps) took the rescue.
bool stepTookRescue(const StepStats& stats, StepRescue rescue);

enum class StepStatus { Ok, NotConverged, NonFinite };

struct EnergyReport {
  double kinetic = 0;
  double gravity = 0;   // potential, relative to the world origin
  double springs = 0;   // elastic potential
  double total() const { return kinetic + gravity + springs; }
};

// One friction-contact problem as a step solved it: U = W P + b over `blocks`,
// the warm start the solver began from and its answer (before any rescue). Seen by a ProblemObserver; the views die with the call.
struct ProblemView {
  double t = 0;   // start of the step
  int round = 0;  // 0, then 1 if contacts closed by the answer joined (late contacts)
  Eigen::Ref<const Eigen::MatrixXd> W;
  Eigen::Ref<const Eigen::VectorXd> b;
  const std::vector<ProblemBlock>& blocks;
  Eigen::Ref<const Eigen::VectorXd> P_start;
  Eigen::Ref<const Eigen::VectorXd> P;
  const SolverReport& report;
  // A substep (Settings::max_step_halvings): of length h / 2^halvings, the
  // substep-th of the step at that length (0 and 0: the step taken whole).
  int halvings = 0;
  int substep = 0;
  // Null for the step's own solve; for a rescue's solve of the step's problem
  // again (rescue_policy.cpp): "cold_retry" (a non-finite answer, solved again
  // from P = 0 by NSGS), "plastic" (an impact that would add energy), "longer"
  // (left unsolved where it may not be halved, solved again with 10 times the budget),
  // "plastic_retry" (left unsolved, solved with e = 0) or "frictionless".
  const char* resolve = nullptr;
};
using ProblemObserver = std::function<void(const ProblemView&)>;

class StepWorkspace;  // preallocated buffers of the pipeline (step_workspace.hpp)
struct StepOutputs;   // what the last step reports (step_workspace.hpp)
struct AdaptiveStepWorkspace;  // the states an adaptive step compares (adaptive_step.hpp)

class Simulator {
 public:
  // Takes the model, places the bodies, runs the assembly projection of the
  // bilateral constraints. Throws std::runtime_error if assembly fails.
  explicit Simulator(Model model);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const Model& model() const { return model_; }
  const State& state() const { return state_; }
  // Continues from a State returned by state() of a simulator of the same model.
  // The outputs of the last step (stats, contacts, forces) are cleared. Throws
  // std::invalid_argument if the sizes do not fit the model or a value is not finite.
  void setState(const State& state);

  // One time step of length model().settings.dt; if its friction-contact problem
  // stays unsolved, taken again in halves (Settings::max_step_halvings,
  // StepStats::substeps; once a smallest substep stays unsolved, the rest of the
  // step is not halved again). NotConverged: a substep kept unsolved.
  // Adaptive step control (Settings::step_control): one step kept, of the length
  // planStep planned (or of the controller's proposal if none was planned), or
  // shorter after rejections; the commands set before it are those at the end of
  // the planned step, and a shorter step ends on the linear interpolation between
  // them and the commands at its start.
  StepStatus step();
  // Adaptive step control: plans the next step, the controller's proposal cut so
  // that it ends at `until` rather than past it or just short of it (a remainder
  // under two steps is split evenly). Returns the time the planned step ends at,
  // where a front end sets the commands (command schedules: scheduled_step.hpp).
  // Fixed step control: state().t + dt, `until` ignored.
  double planStep(double until);
  // Called after every friction-contact solve of step() (for dumps and solver
  // studies); an empty function removes it. Costs a copy of the warm start per
  // solve while set, nothing otherwise.
  void setProblemObserver(ProblemObserver observer);
  // Back to the initial state (after assembly); commands back to their initial
  // values; warm starts and every output of the last step cleared.
  void reset();

  // Actuator inputs. setCommand ignores non-finite values and returns false.
  bool setCommand(int actuator, double value);
  double command(int actuator) const { return state_.commands[actuator]; }
  // Effort of each actuator during the last step (N or N m).
  double actuatorEffort(int actuator) const;
  // Force (N or N m) in each spring at the current state, positive in tension /
  // torque on the joint's child.
  double springForce(int spring) const;

  const StepStats& stats() const;
  const std::vector<ContactReport>& contactPoints() const;  // active contact points of the last step
  EnergyReport energy() const;

  // World pose of a body frame (centre of mass) and of any URDF link.
  Pose bodyPose(int body) const;
  Pose linkPose(int link) const;
  // Angular velocity of a body in the world frame.
  Vec3 angularVelocityWorld(int body) const;

  // Per clearance joint: eccentricity / c_r at mid-bearing, its direction (rad,
  // in the bearing frame), and the summed normal force of its contacts.
  double clearanceEccentricity(int cj) const;
  double clearanceEccentricityAngle(int cj) const;
  double clearanceNormalForce(int cj) const;
  // Joint coordinate, continuous across turns (State::joint_position): rad, or m
  // for a prismatic joint.
  double jointPosition(int joint) const;
  double jointVelocity(int joint) const;  // rad/s or m/s
  // Per named contact: smallest gap (m), summed normal force and |summed tangential force|.
  double contactGap(int pair) const;
  double contactNormalForce(int pair) const;
  double contactTangentialForce(int pair) const;

  // Largest constraint violation of the current state: negative gaps of all
  // candidate contacts (as a positive length) and bilateral position errors.
  double constraintViolation() const;

 private:
  Model model_;
  State state_;
  State initial_state_;
  std::unique_ptr<StepWorkspace> ws_;     // the step's buffers
  std::unique_ptr<StepOutputs> out_;      // what the last step reports
  // Buffers of the const queries (stats(), constraintViolation()): a query never
  // writes the step's workspace, so it cannot change the trajectory.
  std::unique_ptr<StepWorkspace> query_ws_;
  ProblemObserver observer_;
  // Step halving (Settings::max_step_halvings): per level, the command at the end
  // of the interval being halved; the outputs of the substeps, accumulated.
  std::vector<std::vector<double>> halving_commands_;
  std::unique_ptr<StepOutputs> halving_out_;
  // Adaptive step control (adaptive_step.hpp): its buffers, and the step planStep
  // planned (planned_h_ 0: none; planned_end_ NaN: not cut at an end time).
  std::unique_ptr<AdaptiveStepWorkspace> adaptive_;
  double planned_h_ = 0;
  double planned_end_ = 0;
  double planned_proposal_ = 0;

  StepStatus stepWhole(double h);
  StepStatus stepAdaptive();
  // adaptive_step.cpp: one path of an adaptive step, and one attempt (the fine
  // path, and the coarse one unless the fine path's own estimate serves).
  StepStatus takeAdaptivePath(int substeps, double h, double fraction, StepOutputs& forces, bool& event,
                              long& iterations);
  StepStatus attemptAdaptiveStep(double h, double fraction, double& error, bool& event, long& iterations);
  StepStatus advance(double h, int halvings, int substep, bool may_halve);
  StepStatus takeHalves(double h, int level, int index, int& deepest, StepStats& total);
};

}  // namespace nscd
