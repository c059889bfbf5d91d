// Adaptive step control (adaptive_step.hpp): Simulator::planStep and
// Simulator::stepAdaptive. Each attempt of length h is taken along a coarse path
// and a fine one (twice the substeps) from the same State (saved here and
// restored: warm starts, ring hints and commands with it; the narrowphase memo
// keys on the poses, so it cannot serve the wrong ones). Every substep goes
// through stepWhole, so a problem left unsolved is still taken in halves
// (Settings::max_step_halvings) inside it.
#include <algorithm>
#include <cmath>
#include <limits>

#include "adaptive_step.hpp"
#include "step_stages.hpp"

namespace nscd {
namespace {

// The coarse path's substeps (the fine path takes twice as many). Two, not one:
// the velocity a substep ends with satisfies the joints' rows at the configuration
// it started from, so it is off the joints at its own by O(h) (|v| omega h for a
// joint turning at omega), and the rows of ideal joints on the theta-average
// velocity flip that part every substep (theta = 1/2; it never reaches the
// positions, which move with the average). One substep against two would compare
// that part flipped once against flipped twice, an O(h) difference in velocity
// where the scheme's error is O(h^3), and the extrapolation would multiply it
// every step (measured: unstable). Two against four flip it alike.
constexpr int kCoarseSubsteps = 2;
// A rejected smooth step is retried at most this fraction of its length.
constexpr double kRetryAtMost = 0.9;

// Warm starts are impulses, and a contact held by a force takes an impulse in
// proportion to the substep's length. A kept step leaves them scaled to the fine
// substep of the next step it plans (step_next / kFineSubsteps,
// scaleWarmStarts); each path scales them again to its own substep. Unscaled, the
// coarse path began every step from half its impulses, and every retry, or a
// step of another length, from impulses of the wrong length: on the C-60 trip
// (rtol 1e-2) 32 % more solver iterations, at rtol 1e-4 263 rejected steps
// instead of 60 (docs/step_control.md). Only where the State says which length
// they were made for (step_next > 0): not from a fixed run's state.
constexpr int kFineSubsteps = 2 * kCoarseSubsteps;

// The State's warm starts (contacts' and bilateral rows') times `ratio`.
void scaleWarmStarts(double ratio, State& s) {
  if (ratio == 1 || !(ratio > 0) || !std::isfinite(ratio)) return;
  for (Vec3& w : s.warm) w *= ratio;
  for (double& w : s.warm_bilateral) w *= ratio;
}

// The larger in magnitude (as step_halving.cpp: one substep's kinetic change stands for the step).
double largerChange(double a, double b) { return std::abs(b) > std::abs(a) ? b : a; }

// `total` (the stats of a path's earlier substeps) gathered into `last` (the
// substep just taken): counts add, flags and the residual take the worst, the
// contacts, rows and penetration are those of the end.
void gatherStats(const StepStats& total, StepStats& last) {
  last.iterations += total.iterations;
  if (!(total.residual <= last.residual)) last.residual = total.residual;  // NaN stays
  last.converged = total.converged && last.converged;
  last.projection_passes += total.projection_passes;
  last.projection_least_distance += total.projection_least_distance;
  last.plastic_fallback = last.plastic_fallback || total.plastic_fallback;
  last.late_contacts += total.late_contacts;
  last.plastic_retry = last.plastic_retry || total.plastic_retry;
  last.plastic_retry_kinetic_change =
      largerChange(total.plastic_retry_kinetic_change, last.plastic_retry_kinetic_change);
  last.longer_solve = last.longer_solve || total.longer_solve;
  last.frictionless_fallback = last.frictionless_fallback || total.frictionless_fallback;
  last.fallback_kinetic_change =
      largerChange(total.fallback_kinetic_change, last.fallback_kinetic_change);
  last.energy_capped = last.energy_capped || total.energy_capped;
  last.projection_energy_removed += total.projection_energy_removed;
  last.iteration_matrix_fallback = last.iteration_matrix_fallback || total.iteration_matrix_fallback;
  last.substeps = std::max(total.substeps, last.substeps);
  last.halvings = std::max(total.halvings, last.halvings);
}

// Forces and efforts (impulse / length) of a substep, weighted by its share of the path.
void addForces(const StepOutputs& sub, double share, StepOutputs& acc) {
  for (size_t i = 0; i < acc.actuator_effort.size(); ++i)
    acc.actuator_effort[i] += share * sub.actuator_effort[i];
  for (size_t p = 0; p < acc.pair_fn.size(); ++p) {
    acc.pair_fn[p] += share * sub.pair_fn[p];
    acc.pair_ft_vec[p] += share * sub.pair_ft_vec[p];
  }
  for (size_t c = 0; c < acc.cj_fn.size(); ++c) acc.cj_fn[c] += share * sub.cj_fn[c];
}

void clearForces(StepOutputs& acc) {
  std::fill(acc.actuator_effort.begin(), acc.actuator_effort.end(), 0.0);
  std::fill(acc.pair_fn.begin(), acc.pair_fn.end(), 0.0);
  std::fill(acc.pair_ft_vec.begin(), acc.pair_ft_vec.end(), Vec3::Zero());
  std::fill(acc.cj_fn.begin(), acc.cj_fn.end(), 0.0);
}

// out's forces <- the fine path's, extrapolated as the state is when f != 0.
void keepForces(const StepOutputs& fine, const StepOutputs& coarse, double f, StepOutputs& out) {
  auto take = [f](double a, double b) { return a + f * (a - b); };
  for (size_t i = 0; i < out.actuator_effort.size(); ++i)
    out.actuator_effort[i] = take(fine.actuator_effort[i], coarse.actuator_effort[i]);
  for (size_t p = 0; p < out.pair_fn.size(); ++p) {
    out.pair_fn[p] = take(fine.pair_fn[p], coarse.pair_fn[p]);
    for (int k = 0; k < 3; ++k) out.pair_ft_vec[p][k] = take(fine.pair_ft_vec[p][k], coarse.pair_ft_vec[p][k]);
    out.pair_ft[p] = out.pair_ft_vec[p].norm();
  }
  for (size_t c = 0; c < out.cj_fn.size(); ++c) out.cj_fn[c] = take(fine.cj_fn[c], coarse.cj_fn[c]);
}

// The answer of a smooth step (its paths unprojected) onto the joints, as a fixed
// step's projection (Simulator::advance) does, the potential energy it adds
// taken back from the kinetic energy as far as the step from `start` gained energy.
void projectSmoothStep(const Model& m, const State& start, StepWorkspace& ws, State& s, StepStats& st) {
  const Settings& set = m.settings;
  if (!set.projection) return;
  const double pe_before = potentialEnergyOf(m, s).total();
  double violation = 0;
  st.projection_passes = projectPositions(m, s, ws, set.projection_max_iterations, set.projection_tolerance,
                                          violation, st, false);
  if (st.projection_passes > 0)
    st.projection_energy_removed = takeBackProjectionEnergy(m, s.t - start.t, ws, pe_before, StepStartEnergy{&start}, s);
  if (!ws.rows_keyed) clearConstraintRows(ws);
}

}  // namespace

void initAdaptiveStep(const Model& m, const StepWorkspace& ws, const State& state,
                      AdaptiveStepWorkspace& a) {
  a.start = state;
  a.coarse = state;
  const int levels = std::max(2, m.settings.max_order);
  a.row.assign(levels, state.bodies);
  a.cur = state.bodies;
  a.tmp = state.bodies;
  a.errors.assign(levels + 1, 0.0);
  initStepOutputs(m, a.level_out);
  a.end_command = state.commands;
  a.start_command = state.commands;
  initStepOutputs(m, a.coarse_out);
  initStepOutputs(m, a.fine_out);
  initStepOutputs(m, a.fine_report);
  a.fine_substeps.assign(kFineSubsteps + 1, state.bodies);
  // Warm-start slots: kMaxPointsPerPair per contact pair, then kMaxClearancePoints
  // per clearance joint (contact_candidates.cpp, clearance_joint.cpp).
  a.rotation_length.resize(m.bodies.size());
  for (size_t i = 0; i < m.bodies.size(); ++i) a.rotation_length[i] = rotationLength(m, static_cast<int>(i));
  a.slot_mu.assign(ws.facts.contact_slots, 0.0);
  for (int slot = 0; slot < ws.facts.contact_slots; ++slot) {
    const int base = ws.facts.contact_slot_base_clearance;
    a.slot_mu[slot] = slot < base ? m.contacts[slot / kMaxPointsPerPair].mu
                                  : m.clearance_joints[(slot - base) / kMaxClearancePoints].mu;
  }
}

double Simulator::planStep(double until) {
  const Settings& set = model_.settings;
  if (set.step_control != StepControl::Adaptive) return state_.t + set.dt;
  const StepLengths lim = stepLengths(set);
  // Clamped both ways: a state set from outside (a state file, set_state) may hold
  // any step_next >= 0; 5e-324 s made the forces (impulse / h) infinite.
  const double proposal = state_.step_next > 0 ? std::clamp(state_.step_next, lim.h_min, lim.h_max) : lim.h_max;
  double h = proposal;
  planned_end_ = NAN;
  const double remaining = until - state_.t;
  if (remaining > 0 && remaining <= h * (1 + 1e-9)) {
    h = remaining;
    planned_end_ = until;
  } else if (remaining > h && remaining < 2 * h) {
    h = 0.5 * remaining;  // two even steps rather than one and a sliver
  }
  planned_h_ = h;
  planned_proposal_ = proposal;
  // The commands now are those the step starts from (a front end with schedules
  // has set them to their values just after t: prepareScheduledStep); a step cut
  // short ends on the line from them to the commands set for the planned end.
  std::copy(state_.commands.begin(), state_.commands.end(), adaptive_->start_command.begin());
  return std::isnan(planned_end_) ? state_.t + h : planned_end_;
}

// n substeps of length h / n from a.start (in state_), the commands linear from
// a.start_command to those at t0 + fraction h_plan (a.end_command); forces
// averaged into `forces`, stats gathered into out_->stats; `event`: a substep had
// a nonsmooth event or left a contact in another mode than at the start.
StepStatus Simulator::takeAdaptivePath(int n, double h, double fraction, StepOutputs& forces, bool& event,
                                       long& iterations) {
  AdaptiveStepWorkspace& a = *adaptive_;
  StepStatus worst = StepStatus::Ok;
  StepStats total;
  event = false;
  clearForces(forces);
  // The State's warm starts were made for a substep of a.start.step_next / kFineSubsteps.
  if (a.start.step_next > 0) scaleWarmStarts((h / n) / (a.start.step_next / kFineSubsteps), state_);
  a.kept_substep = h / n;
  const bool record = n == kFineSubsteps;  // the fine path's bodies, for embeddedEventError
  if (record) a.fine_substeps[0] = state_.bodies;  // same sizes: no allocation
  for (int i = 1; i <= n; ++i) {
    const double f = i == n ? fraction : fraction * i / n;
    for (size_t c = 0; c < a.end_command.size(); ++c) {
      const double c0 = a.start_command[c], c1 = a.end_command[c];
      state_.commands[c] = f == 1 ? c1 : c0 + f * (c1 - c0);
    }
    const StepStatus s = stepWhole(h / n);
    iterations += out_->stats.iterations;
    if (s == StepStatus::NonFinite) return s;
    if (s == StepStatus::NotConverged) worst = s;
    if (record) a.fine_substeps[i] = state_.bodies;
    event = event || stepHadEvent(out_->stats) || !sameContactModes(a.slot_mu, a.start, state_);
    addForces(*out_, 1.0 / n, forces);
    if (i > 1) gatherStats(total, out_->stats);
    total = out_->stats;
    if (event && a.stop_at_event) return worst;  // the path is taken again (attemptAdaptiveStep)
  }
  return worst;
}

// One attempt of length h from a.start. Where every contact is open at the
// start (below), the coarse path first: an event on it ends the unprojected
// paths at once. Else the fine path first (left in state_): if it had a nonsmooth
// event, its answer is the step's (first order) and the coarse path is not taken:
// the error is embeddedEventError's, from the fine path's own substeps (4
// substep solves where the paths take 6). So too where the fine path had no
// event, the step is at dt and the fine path's own estimate (counted as a
// velocity, as the paths' difference is) is far within the tolerance
// (cappedWellWithinTolerance): the coarse path would only confirm an error that
// cannot lengthen the step, and buy the extrapolation of an answer already well
// within the tolerance; the fine path's answer is kept. Otherwise the coarse path (kept in
// a.coarse) and the paths' scaled difference. Where a contact changed mode on the
// coarse path alone, velocities jump: the paths' velocities differ by O(1)
// whenever one has met the event and the other not yet, however short the step.
// Their difference then counts as the displacement it makes over the step
// (weight h), which a shorter step does reduce: the event is located in time.
StepStatus Simulator::attemptAdaptiveStep(double h, double fraction, double& error, bool& event,
                                          long& iterations) {
  AdaptiveStepWorkspace& a = *adaptive_;
  const Settings& set = model_.settings;
  StepStatus coarse = StepStatus::Ok, fine = StepStatus::Ok;
  auto takeCoarse = [&](bool& coarse_event) {
    state_ = a.start;  // same sizes: no allocation
    coarse = takeAdaptivePath(kCoarseSubsteps, h, fraction, a.coarse_out, coarse_event, iterations);
    a.coarse_out.stats = out_->stats;
  };
  auto differenceOfPaths = [&]() {
    const bool finite = fine != StepStatus::NonFinite && coarse != StepStatus::NonFinite;
    error = finite ? scaledStateDifference(a.coarse, state_, set.atol, set.rtol, event ? h : 1.0, a.rotation_length)
                   : INFINITY;
  };
  // Every contact open at the start: the coarse path first, ended by an event.
  auto takeUnprojectedPaths = [&]() {
    bool coarse_event = false, fine_event = false;
    a.coarse_taken = true;
    takeCoarse(coarse_event);
    if (coarse_event) {
      event = true;
      error = INFINITY;
      return;
    }
    a.coarse = state_;
    state_ = a.start;
    fine = takeAdaptivePath(kFineSubsteps, h, fraction, a.fine_out, fine_event, iterations);
    event = fine_event;
    differenceOfPaths();
  };
  auto takePaths = [&]() {
    bool coarse_event = false, fine_event = false;
    state_ = a.start;
    fine = takeAdaptivePath(kFineSubsteps, h, fraction, a.fine_out, fine_event, iterations);
    a.coarse_taken = false;
    if (fine != StepStatus::NonFinite) {
      if (fine_event) {
        event = true;
        error = embeddedEventError(a.fine_substeps, kFineSubsteps, h, set.atol, set.rtol, a.rotation_length);
        return;
      }
      const StepLengths lim = stepLengths(set);
      if (atLargestStep(lim, h)) {
        error = embeddedEventError(a.fine_substeps, kFineSubsteps, h, set.atol, set.rtol, a.rotation_length, true);
        if (cappedWellWithinTolerance(lim, h, error)) {
          event = false;
          return;
        }
      }
    }
    a.coarse_taken = true;
    // The fine path's State and outputs set aside (swapped: no allocation) while
    // the coarse path is taken, then put back.
    std::swap(state_, a.coarse);
    std::swap(*out_, a.fine_report);
    takeCoarse(coarse_event);
    std::swap(state_, a.coarse);
    std::swap(*out_, a.fine_report);
    a.kept_substep = h / kFineSubsteps;  // the warm starts in state_ are the fine path's
    event = coarse_event || fine_event;
    differenceOfPaths();
  };
  a.order = 2;
  a.tableau = false;
  a.project_substeps = true;
  // A step that starts with every contact open may be smooth: its paths are
  // then taken without the projection, so that each is a smooth function of its
  // substep length (a projection only where the drift passes a threshold is not),
  // and extrapolated as far as the tolerance asks (max_order); its answer is
  // projected once (stepAdaptive). If anything nonsmooth happens on any path,
  // the coarse and fine paths are taken again with the projection, as below.
  if (set.max_order > 2 && contactsOpen(a.slot_mu, a.start)) {
    a.project_substeps = false;
    // Unprojected paths with an event are of no use: stop at the first one.
    a.stop_at_event = true;
    takeUnprojectedPaths();
    StepStatus status = fine;
    if (!event && error < INFINITY) {
      a.tableau = true;
      a.errors[2] = error;
      if (error <= 1) {  // the paths' combination (stepAdaptive)
        a.project_substeps = true;
        a.stop_at_event = false;
        return status;
      }
      addTableauLevel(0, a.coarse.bodies, a);
      addTableauLevel(1, state_.bodies, a);
      for (int j = 2; j < set.max_order && !event; ++j) {
        state_ = a.start;
        const StepStatus s = takeAdaptivePath(levelSubsteps(j), h, fraction, a.level_out, event, iterations);
        if (s == StepStatus::NonFinite) event = true;
        if (event) break;
        if (s == StepStatus::NotConverged) status = s;
        addTableauLevel(j, state_.bodies, a);
        error = scaledBodiesDifference(a.row[j - 1], a.cur, set.atol, set.rtol, 1.0, a.rotation_length);
        a.errors[j + 1] = error;
        a.order = j + 1;
        if (error <= 1) break;
      }
      if (!event) {
        state_.bodies = a.cur;  // T_{k,k}, with the finest path's warm starts and hints
        a.project_substeps = true;
        a.stop_at_event = false;
        return status;
      }
    }
    // Not smooth after all (or the paths not finite): taken again as below.
    a.project_substeps = true;
    a.stop_at_event = false;
    a.order = 2;
    a.tableau = false;
  }
  takePaths();
  return fine;
}

StepStatus Simulator::stepAdaptive() {
  const Model& m = model_;
  const Settings& set = m.settings;
  AdaptiveStepWorkspace& a = *adaptive_;
  if (!(planned_h_ > 0)) {  // no plan: the step starts from the commands the last one ended on
    planStep(INFINITY);
    std::copy(state_.prev_commands.begin(), state_.prev_commands.end(), a.start_command.begin());
  }
  const double h_plan = planned_h_, end_plan = planned_end_, proposal = planned_proposal_;
  planned_h_ = 0;
  const StepLengths lim = stepLengths(set);
  const double t0 = state_.t;
  a.start = state_;  // same sizes: no allocation
  a.end_command = state_.commands;

  long iterations = 0;
  int rejected = 0;
  double h = h_plan, error = 0;
  bool event = false;
  StepStatus status = StepStatus::Ok;
  bool unsolved = false;  // kept although its error is above 1 (below)
  for (;;) {
    status = attemptAdaptiveStep(h, h == h_plan ? 1.0 : h / h_plan, error, event, iterations);
    if (error <= 1 || h <= lim.h_min) break;
    // A substep kept unsolved although it was halved (Simulator::takeHalves): the
    // paths' difference is then that of unsolved answers, which a shorter step does
    // not make solved. Kept, as a fixed step would be.
    unsolved = status == StepStatus::NotConverged && set.max_step_halvings > 0;
    if (unsolved) break;
    ++rejected;
    h = a.tableau ? extrapolationStepLength(lim, h, a.errors, a.order, set.max_order, kRetryAtMost)
                  : retryStepLength(lim, h, error);
  }

  StepStats& st = out_->stats;
  st.iterations = static_cast<int>(std::min<long>(iterations, std::numeric_limits<int>::max()));
  st.h = h;
  st.rejected = rejected;
  st.error = error;
  if (status == StepStatus::NonFinite) return status;
  // Nothing nonsmooth on either path, every contact in the mode it ended the last
  // step in: the fine path's answer extrapolated (where the coarse one was taken).
  const bool extrapolate = !event && a.coarse_taken;
  const double f = extrapolate ? kRichardsonFactor : 0.0;
  if (extrapolate) {
    if (a.order == 2) richardsonExtrapolate(a.coarse, f, state_);  // else the tableau's answer is in state_
    if (a.tableau) projectSmoothStep(m, a.start, *ws_, state_, st);
    trackJointPositions(m, state_);
  }
  keepForces(a.fine_out, a.coarse_taken ? a.coarse_out : a.fine_out, f, *out_);
  st.extrapolated = extrapolate;
  state_.t = h == h_plan && !std::isnan(end_plan) ? end_plan : t0 + h;
  double next = a.tableau ? extrapolationStepLength(lim, h, a.errors, a.order, set.max_order,
                                                    rejected > 0 ? 1.0 : INFINITY)
                          : nextStepLength(lim, h, error, a.start.step_error, rejected > 0);
  if (unsolved) next = h;  // its estimate says nothing of the step's length
  // A step cut short to end at a given time is no reason for the next to be short.
  if (rejected == 0 && h < proposal) next = std::max(next, proposal);
  state_.step_next = next;
  // The warm starts (of the last path's substeps, a.kept_substep) for the next step's fine substep.
  scaleWarmStarts((next / kFineSubsteps) / a.kept_substep, state_);
  state_.step_error = unsolved ? 1.0 : std::min(error, 1e3);
  return status;
}

}  // namespace nscd
