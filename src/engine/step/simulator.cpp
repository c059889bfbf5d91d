// The Simulator: one Model, one State, and a time step that reads as its stages
// (step_stages.hpp, one file each). Queries read the State and the outputs of the
// last step; none of them writes the step's workspace.
#include "nscd_sim/simulator.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "adaptive_step.hpp"
#include "joints/clearance_joint.hpp"
#include "geometry/contact_pair.hpp"
#include "step_stages.hpp"

namespace nscd {
namespace {

// Re-solves per step for contacts closed by the answer (activateLateContacts).
constexpr int kLateActivationRounds = 3;

// The stages of Simulator::advance that take more than one call.

// Outputs and rows cleared (but rows gathered at the state's poses, the last
// step's last check, in a model whose rows follow the poses), the commanded
// rates of the step, the ring hints kept while the step may still be taken
// again in halves.
void beginStep(double h, bool may_halve, const State& s, StepWorkspace& ws, StepOutputs& out) {
  if (may_halve) copyRingHints(s.ring_hint, ws.halving_hint);  // same size: no allocation
  clearStepOutputs(out);
  if (!rowsMatchPoses(s, ws)) clearConstraintRows(ws);
  for (size_t i = 0; i < s.commands.size(); ++i) ws.rates[i] = (s.commands[i] - s.prev_commands[i]) / h;
}

// 1. Forces, the iteration matrix and the free velocity.
void computeFreeMotion(const Model& m, double h, const State& s, StepWorkspace& ws, StepOutputs& out) {
  computeForces(m, s, ws, out, ws.facts.stiff);
  stateVelocities(s, ws.vk);
  buildIterationMatrix(m, h, ws, out.stats);
  computeFreeVelocity(m, h, ws);
}

// 2. The ideal joints' rows, then the contacts that can close in the step (none
// to look for in a model without contact pairs and clearance joints).
void gatherStepRows(const Model& m, double h, State& s, StepWorkspace& ws) {
  if (ws.rows_keyed) return;  // kept from the last check (beginStep): the same rows
  appendBilateralRows(m, s, ws.rates, ws);
  if (!hasContactSources(ws)) return;
  if (m.settings.contact_prediction > 0) predictState(s, m.settings.contact_prediction * h, ws.predicted);
  findContactCandidates(m, s, h, CandidateMode::Step, 0.0, s.ring_hint.data(), ws);
  activateContacts(m, s, h, CandidateMode::Step, ws);
}

// 3-4. The Delassus operator, the problem, its solve and rescues; contacts the
// answer closes (a light body kicked from one joint into another) join, and the
// problem is solved again from this answer, up to kLateActivationRounds times.
void solveStepProblem(const Model& m, double h, const State& s, bool may_halve, ResolveObserver observe,
                      StepWorkspace& ws, StepStats& st) {
  st.rows = ws.rows;
  ws.equality.factor_rows = 0;
  if (ws.rows == 0) {
    ws.vnew = ws.vfree;
    return;
  }
  // Bilateral rows alone: one LDLᵀ solve (an observer sees the general path's problems).
  if (!hasContactSources(ws) && !observe.fn && solveEqualityStep(m, ws, st)) return;
  int kept = 0, iterations = 0;
  for (observe.round = 0;; ++observe.round) {
    assembleDelassus(ws.iteration_inverse, !ws.facts.stiff, ws, kept, ws.rows);
    buildFrictionContactProblem(m, s, h, kept, ws, st);
    const SolverReport rep = solveWithRescues(m, ws, solverOptions(m.settings), may_halve, observe, st);
    iterations += rep.iteration_sum;
    st.iterations = iterations;
    st.residual = rep.residual;
    st.converged = rep.converged;
    if (observe.round == kLateActivationRounds) break;
    kept = ws.rows;
    const int added = activateLateContacts(m, s, h, ws);
    if (added == 0) break;
    st.late_contacts += added;
  }
  st.rows = ws.rows;
}

// 6. The projection, when the settings ask for it, and the potential energy it
// adds beyond the inputs' work in the step taken back from the kinetic energy, as
// far as the step gained energy from its start (potential_start: the start's
// potential energy; its velocities are still in ws.vk).
// (Left in, it drove the C-60's released hook to 1e4 rad/s: the ideal-joint
// model went from 0.19 to 0.8 J in 2.5 ms, 0.18 J with the projection off.)
// reuse: velocityFactorReusable, asked before the update.
// project: false in the paths of a smooth adaptive step, which are projected once
// at its end (adaptive_step.cpp: the threshold would break their smoothness in h).
void projectStep(const Model& m, double h, bool reuse, bool project, double potential_start, State& s,
                 StepWorkspace& ws, StepOutputs& out) {
  const Settings& set = m.settings;
  StepStats& st = out.stats;
  if (!set.projection || !project) {
    // Measured when asked for (stats()): it costs a geometry pass, as much as
    // the contact search itself, and most callers never read it.
    out.penetration_pending = true;
    return;
  }
  const double pe_before = potentialEnergyOf(m, s).total();
  const double input_work = inputWorkOfStep(m, h, ws, out, s);
  double violation = 0;
  st.projection_passes = projectPositions(m, s, ws, set.projection_max_iterations, set.projection_tolerance,
                                          violation, st, reuse);
  if (st.projection_passes > 0)
    st.projection_energy_removed = takeBackProjectionEnergy(
        m, h, ws, pe_before + input_work, StepStartEnergy{nullptr, &ws.vk, potential_start, input_work}, s);
  st.max_penetration = 0;  // of the rows of the last pass
  for (const ConstraintBlock& blk : ws.blocks)
    if (blk.kind != BlockKind::Bilateral) st.max_penetration = std::max(st.max_penetration, -blk.contact.cp.gap);
}

bool stateFinite(const StepWorkspace& ws, const State& s) {
  bool finite = ws.vnew.allFinite();
  for (const BodyState& b : s.bodies) finite = finite && b.x.allFinite() && b.q.coeffs().allFinite();
  return finite;
}

}  // namespace

Simulator::Simulator(Model model)
    : model_(std::move(model)), ws_(new StepWorkspace), out_(new StepOutputs),
      query_ws_(new StepWorkspace), halving_out_(new StepOutputs),
      adaptive_(new AdaptiveStepWorkspace) {
  const Model& m = model_;
  initStepWorkspace(m, *ws_);
  initStepWorkspace(m, *query_ws_);
  initStepOutputs(m, *out_);
  initStepOutputs(m, *halving_out_);
  state_ = initialState(m, *ws_);
  placeJournals(m, state_);
  assembleState(m, state_, *ws_);  // positions and velocities onto the constraints
  initial_state_ = state_;
  // Sized once: a halving copies commands without allocating.
  halving_commands_.assign(m.settings.max_step_halvings + 1, state_.commands);
  if (m.settings.step_control == StepControl::Adaptive) initAdaptiveStep(m, *ws_, state_, *adaptive_);
}

Simulator::~Simulator() = default;

void Simulator::reset() {
  state_ = initial_state_;
  planned_h_ = 0;
  ws_->narrow.valid = false;  // its key would tell too; no memo outlives a jump
  clearStepOutputs(*out_);
}

void Simulator::setState(const State& s) {
  const State& ref = initial_state_;
  if (s.bodies.size() != ref.bodies.size() || s.commands.size() != ref.commands.size() ||
      s.prev_commands.size() != ref.prev_commands.size() || s.warm.size() != ref.warm.size() ||
      s.warm_valid.size() != ref.warm_valid.size() ||
      s.warm_bilateral.size() != ref.warm_bilateral.size() ||
      s.ring_hint.size() != ref.ring_hint.size() || s.joint_position.size() != ref.joint_position.size())
    throw std::invalid_argument("setState: the state was not made for this model (sizes differ)");
  bool finite = std::isfinite(s.t);
  for (const BodyState& b : s.bodies)
    finite = finite && b.x.allFinite() && b.q.coeffs().allFinite() && b.v.allFinite() &&
             b.w.allFinite();
  for (double c : s.commands) finite = finite && std::isfinite(c);
  for (double c : s.prev_commands) finite = finite && std::isfinite(c);
  for (double a : s.joint_position) finite = finite && std::isfinite(a);
  finite = finite && std::isfinite(s.step_next) && std::isfinite(s.step_error);
  if (!finite) throw std::invalid_argument("setState: the state holds a non-finite value");
  if (s.step_next < 0 || s.step_error < 0)
    throw std::invalid_argument("setState: step_next and step_error must be >= 0");
  state_ = s;
  planned_h_ = 0;
  ws_->narrow.valid = false;  // its key would tell too; no memo outlives a jump
  clearStepOutputs(*out_);
}

bool Simulator::setCommand(int actuator, double value) {
  if (actuator < 0 || actuator >= static_cast<int>(state_.commands.size()) ||
      !std::isfinite(value))
    return false;
  state_.commands[actuator] = value;
  return true;
}

StepStatus Simulator::step() {
  if (model_.settings.step_control == StepControl::Adaptive) return stepAdaptive();
  const StepStatus status = stepWhole(model_.settings.dt);
  out_->stats.h = model_.settings.dt;
  return status;
}

// One step of length h, taken again in halves while its problem stays unsolved.
StepStatus Simulator::stepWhole(double h) {
  int deepest = model_.settings.max_step_halvings;
  const StepStatus whole = advance(h, 0, 0, deepest > 0);
  if (whole != StepStatus::NotConverged || deepest == 0) return whole;
  // Unsolved: taken again from its start (advance left the state as it found it)
  // as two steps of h/2 (step_halving.cpp). The attempt's work is counted.
  StepStats total;
  startHalvedStep(out_->stats, total, *halving_out_);
  const StepStatus halves = takeHalves(h, 1, 0, deepest, total);
  finishHalvedStep(total, *halving_out_, *out_);
  return halves;
}

// [t, t + h] as two steps of h/2 (level: h/2 = dt / 2^level); each taken again in
// halves while unsolved, down to level `deepest` (max_step_halvings). Once a
// substep is left unsolved where it could not be halved, halving has not settled
// the step: deepest drops to 0 and the rest of the interval is taken in the
// substeps already begun, each once (with every rescue). A step the solver can
// never settle then costs 2 L + 1 attempts, not the 2^(L+1) - 1 of the whole
// tree (L = max_step_halvings). state_.commands holds the command at the end of
// the interval, state_.prev_commands the one at its start: the first half ends
// on their mean (a prescribed motion keeps its rate).
StepStatus Simulator::takeHalves(double h, int level, int index, int& deepest, StepStats& total) {
  std::vector<double>& end_command = halving_commands_[level];
  end_command = state_.commands;
  for (int half = 0; half < 2; ++half) {
    for (size_t i = 0; i < end_command.size(); ++i)
      state_.commands[i] =
          half == 0 ? 0.5 * (state_.prev_commands[i] + end_command[i]) : end_command[i];
    const bool may_halve = level < deepest;
    StepStatus s = advance(0.5 * h, level, 2 * index + half, may_halve);
    if (s == StepStatus::NotConverged && may_halve) {
      addDroppedAttempt(out_->stats, total);
      s = takeHalves(0.5 * h, level + 1, 2 * index + half, deepest, total);
    } else {
      if (s == StepStatus::NotConverged) deepest = 0;
      addSubstep(out_->stats, level, *out_, total, *halving_out_);
    }
    if (s == StepStatus::NonFinite) return s;
  }
  return total.converged ? StepStatus::Ok : StepStatus::NotConverged;
}

// One step (or a substep `halvings` halvings deep) of length h, as its stages. If
// it is left unsolved while it may still be halved, it returns NotConverged with the
// State as it found it: every stage before that point reads the State (const),
// but for the ring hints of the contact search, which are put back.
StepStatus Simulator::advance(double h, int halvings, int substep, bool may_halve) {
  const Model& m = model_;
  StepWorkspace& ws = *ws_;
  StepStats& st = out_->stats;
  beginStep(h, may_halve, state_, ws, *out_);
  // 1. forces, iteration matrix, free velocity
  computeFreeMotion(m, h, state_, ws, *out_);
  // 2. constraint rows: ideal joints, then the contacts that can close in the step
  gatherStepRows(m, h, state_, ws);
  // 3-4. Delassus operator, problem, solve and rescues, contacts the answer closes
  const ProblemObserver* observe = observer_ ? &observer_ : nullptr;
  solveStepProblem(m, h, state_, may_halve, ResolveObserver{observe, state_.t, 0, halvings, substep}, ws, st);
  // Unsolved, and the step can still be halved: the caller takes it again.
  if (!st.converged && may_halve) {
    state_.ring_hint = ws.halving_hint;
    return StepStatus::NotConverged;
  }
  storeImpulses(m, h, state_, ws, *out_);
  // 5. update
  const bool reuse = velocityFactorReusable(h, ws);
  const bool project = m.settings.projection && adaptive_->project_substeps;
  // The start's kinetic energy, if the take-back needs it, from ws.vk (its velocities).
  const double potential_start = project ? potentialEnergyOf(m, state_).total() : 0.0;
  advanceState(m, h, ws, state_);
  // 6. projection, and the energy it must not add
  projectStep(m, h, reuse, project, potential_start, state_, ws, *out_);
  if (!ws.rows_keyed) clearConstraintRows(ws);
  trackJointPositions(m, state_);
  if (!stateFinite(ws, state_)) return StepStatus::NonFinite;
  return st.converged ? StepStatus::Ok : StepStatus::NotConverged;
}

void Simulator::setProblemObserver(ProblemObserver observer) {
  observer_ = std::move(observer);
  if (observer_) ws_->P_start.resize(ws_->P.size());
}

double Simulator::actuatorEffort(int actuator) const { return out_->actuator_effort[actuator]; }
double Simulator::springForce(int spring) const { return springForceAt(model_, state_, spring); }

const StepStats& Simulator::stats() const {
  StepOutputs& out = *out_;
  if (out.penetration_pending) {  // the last step had no projection (see step())
    out.penetration_pending = false;
    out.stats.max_penetration = measureViolation(model_, state_, *query_ws_);
  }
  return out.stats;
}

const std::vector<ContactReport>& Simulator::contactPoints() const { return out_->reports; }

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

double Simulator::clearanceEccentricity(int cj) const {
  return journalEccentricity(state_, model_.clearance_joints[cj]);
}

double Simulator::clearanceEccentricityAngle(int cj) const {
  return journalEccentricityAngle(state_, model_.clearance_joints[cj]);
}

double Simulator::clearanceNormalForce(int cj) const { return out_->cj_fn[cj]; }

double Simulator::contactGap(int pair) const {
  return contactPairGap(state_, model_.contacts[pair]);
}

double Simulator::jointPosition(int joint) const { return nscd::jointPosition(model_, state_, joint); }
double Simulator::jointVelocity(int joint) const { return nscd::jointVelocity(model_, state_, joint); }

double Simulator::contactNormalForce(int pair) const { return out_->pair_fn[pair]; }
double Simulator::contactTangentialForce(int pair) const { return out_->pair_ft[pair]; }

double Simulator::constraintViolation() const {
  double bil = 0;
  const double pen = measureViolation(model_, state_, *query_ws_, &bil);
  return std::max(pen, bil);
}

}  // namespace nscd
