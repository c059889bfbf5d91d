// Stage 4c: the step's friction-contact solve and the rescues of a solve that
// goes wrong, as one ordered policy (StepRescue, simulator.hpp), each counted in
// StepStats and each re-solve shown to the problem observer:
// - ColdRetry: a non-finite answer (a Newton stage blew up) is never applied: the
//   problem is solved again from P = 0 by plain NSGS, which the later re-solves
//   of the step then use too.
// - PlasticImpact: Newton's impact law at several coupled frictional points can
//   add kinetic energy (it is only proven dissipative for one point), and with
//   theta = 1/2 the impulses can do positive work over the step: the impact is
//   then taken plastic (e = 0).
// - Halving: while the step can still be halved (Settings::max_step_halvings) an
//   unsolved problem is left as it is, and the step is taken again as two of h/2
//   (Simulator::step, step_halving.cpp): within one step a light link can cross
//   a tight bearing, so that contacts on both sides of it enter one problem with
//   Newton's law on each, which may have no solution, while in h/2 or h/4 the
//   link meets one side at a time. The rescues below wait for a step that may
//   not be halved (the smallest, or one after a smallest left unsolved: see
//   Simulator::takeHalves): they cost ten solves or change the physics.
// - LongerSolve: a problem left unsolved is solved again from its answer with 10
//   times the budget (jammed sets with impulses 100 times the usual can need
//   1 000 to 1 500 Newton iterations); the better of the two answers stays.
// - PlasticRetry: a problem with restitution left unsolved: Newton's law at
//   coupled points may have no solution (a link bounced off one contact into
//   another within the step, which no velocity can meet) where the plastic law
//   has one. Solved again with e = 0, friction kept; if that converges it is the
//   step's answer, else the unsolved answer stays.
// - Frictionless: a problem left unsolved whose answer adds kinetic energy
//   through the contacts, or far from solved (residual > 1e-3; it may have no
//   solution: Coulomb friction at coupled points), can pump energy into the
//   mechanism or drive bodies through each other: the step is taken frictionless
//   and plastic, a convex problem. (An exact answer with e = 0 never adds energy
//   through its contacts; an unsolved one can.)
// - EnergyCap: still far from solved: the impulses are scaled so they add no
//   kinetic energy.
#include <algorithm>
#include <cmath>

#include "step_stages.hpp"

namespace nscd {
namespace {

// The budget of the longer solve, in multiples of the run's.
constexpr int kLongerBudget = 10;
// Residual above which an unconverged frictional answer is replaced.
constexpr double kFrictionlessFallbackResidual = 1e-3;
// Kinetic energy (relative to K(v_free)) an unsolved answer may add through its
// contacts before it is replaced: above round-off, far below a real gain.
constexpr double kUnsolvedEnergyGain = 1e-9;

// What the rescues read and change: the step's problem and answer (ws), its
// stats, the solver options (ColdRetry changes the method), the report of the
// answer that stands, and whether restitution has been taken out.
struct RescueContext {
  const Model& m;
  StepWorkspace& ws;
  StepStats& st;
  const ResolveObserver& observe;
  bool may_halve;
  SolverOptions options;
  SolverReport rep;
  bool plastic = false;
};

// The step's problem as it now stands (b and mu as the rescues set them),
// solved again from the current answer and shown to the observer as `kind`.
SolverReport solveAgain(RescueContext& c, const char* kind, const SolverOptions& with) {
  StepWorkspace& ws = c.ws;
  const int r = ws.rows;
  const auto W = ws.W.topLeftCorner(r, r);
  const auto b = ws.b.head(r);
  const ResolveObserver& o = c.observe;
  if (o.fn) ws.P_start.head(r) = ws.P.head(r);
  const SolverReport again = ws.solver.solve(W, b, ws.problem, with, ws.P.head(r));
  ++c.st.solves_by_stage[static_cast<int>(again.stage)];
  if (o.fn)
    (*o.fn)(ProblemView{o.t, o.round, W, b, ws.problem, ws.P_start.head(r), ws.P.head(r), again,
                        o.halvings, o.substep, kind});
  return again;
}

// Whether the impulses add energy, by either of two measures (the second only
// with_work), each compared with K(v_free):
// - the kinetic energy they add, Phi = sum_c P_c.u+_c - P.W.P/2 (the change
//   K(v+) - K(v_free) minus the work of the bilateral rows' targets). With e = 0
//   every term is <= 0 (u_N+ P_N = 0, friction opposes u_T+);
// - their work over the step, sum_c P_c.(theta u+_c + (1 - theta) u_k,c): the
//   positions move with that velocity, so with gravity alone this is the step's
//   energy change. It can be positive where a contact separates at the start of
//   the step, or where friction that stops a sliding point at its end points
//   along the sliding at its start.
// rel_tol: the gain tolerated, relative to K(v_free). An impact with restitution
// is checked by both; an unsolved answer by Phi only (an exact answer's work can
// be positive, its Phi cannot).
bool impulsesGainEnergy(const Model& m, const StepWorkspace& ws, double rel_tol, bool with_work) {
  const auto G = ws.G.topRows(ws.rows);
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
  const double tol = rel_tol * kineticEnergyOf(m, ws.vfree) + 1e-300;
  return (std::isfinite(phi) && phi > tol) || (with_work && std::isfinite(work) && work > tol);
}

bool anyRestitution(const StepWorkspace& ws) {
  for (const ConstraintBlock& blk : ws.blocks)
    if (blk.kind != BlockKind::Bilateral && blk.contact.e > 0) return true;
  return false;
}

// The change of the kinetic energy of v+ from k_before, relative to K(v_free).
double kineticChange(const RescueContext& c, double k_before) {
  return (kineticEnergyOf(c.m, c.ws.vnew) - k_before) / (kineticEnergyOf(c.m, c.ws.vfree) + 1e-300);
}

// ---- ColdRetry
bool answerNotFinite(const RescueContext& c) {
  const int r = c.ws.rows;
  return !c.ws.P.head(r).allFinite() && c.ws.W.topLeftCorner(r, r).allFinite() && c.ws.b.head(r).allFinite();
}
void retryCold(RescueContext& c) {
  c.ws.P.head(c.ws.rows).setZero();
  c.options.method = SolverMethod::NSGS;
  c.rep = solveAgain(c, "cold_retry", c.options);
  applyImpulses(c.ws);
  c.st.cold_retry = true;
}

// ---- PlasticImpact
bool impactGainsEnergy(const RescueContext& c) {
  return c.st.active_contacts > 0 && anyRestitution(c.ws) && impulsesGainEnergy(c.m, c.ws, 1e-12, true);
}
void solvePlastic(RescueContext& c) {
  removeRestitution(c.ws);
  c.rep = solveAgain(c, "plastic", c.options);
  applyImpulses(c.ws);
  c.plastic = c.st.plastic_fallback = true;
}

// ---- Halving (no action here: the policy stops, Simulator::step halves)
bool stepCanBeHalved(const RescueContext& c) { return c.may_halve; }

// ---- LongerSolve
bool unsolved(const RescueContext& c) { return !c.rep.converged && c.st.active_contacts > 0; }
void solveLonger(RescueContext& c) {
  StepWorkspace& ws = c.ws;
  const int r = ws.rows;
  ws.retry_P.head(r) = ws.P.head(r);
  SolverOptions longer = c.options;
  longer.max_iterations = c.options.max_iterations * kLongerBudget;
  const SolverReport rep_l = solveAgain(c, "longer", longer);
  c.rep.iteration_sum += rep_l.iteration_sum;
  if (rep_l.converged || rep_l.residual < c.rep.residual) {
    c.rep.residual = rep_l.residual;
    c.rep.converged = rep_l.converged;
    applyImpulses(ws);
    c.st.longer_solve = true;
  } else {
    ws.P.head(r) = ws.retry_P.head(r);
  }
}

// ---- PlasticRetry
bool unsolvedWithRestitution(const RescueContext& c) { return unsolved(c) && !c.plastic && anyRestitution(c.ws); }
void retryPlastic(RescueContext& c) {
  StepWorkspace& ws = c.ws;
  const int r = ws.rows;
  ws.retry_P.head(r) = ws.P.head(r);
  ws.retry_b.head(r) = ws.b.head(r);
  const double k_unsolved = kineticEnergyOf(c.m, ws.vnew);
  removeRestitution(ws);
  const SolverReport rep_p = solveAgain(c, "plastic_retry", c.options);
  c.rep.iteration_sum += rep_p.iteration_sum;
  if (rep_p.converged) {
    c.rep.residual = rep_p.residual;
    c.rep.converged = true;
    applyImpulses(ws);
    c.plastic = c.st.plastic_retry = true;
    c.st.plastic_retry_kinetic_change = kineticChange(c, k_unsolved);
  } else {
    ws.P.head(r) = ws.retry_P.head(r);
    ws.b.head(r) = ws.retry_b.head(r);
  }
}

// ---- Frictionless
bool farOffOrGainsEnergy(const RescueContext& c) {
  return unsolved(c) && (!(c.rep.residual <= kFrictionlessFallbackResidual) ||
                         impulsesGainEnergy(c.m, c.ws, kUnsolvedEnergyGain, false));
}
void solveFrictionless(RescueContext& c) {
  StepWorkspace& ws = c.ws;
  // Frictionless and plastic; the problem blocks are rebuilt by the next assembly.
  const double k_unsolved = kineticEnergyOf(c.m, ws.vnew);
  if (!c.plastic) removeRestitution(ws);
  for (ProblemBlock& pb : ws.problem) pb.mu = 0;
  const SolverReport rep0 = solveAgain(c, "frictionless", c.options);
  if (!ws.P.head(ws.rows).allFinite()) return;
  c.rep.iteration_sum += rep0.iteration_sum;
  c.rep.residual = rep0.residual;
  c.rep.converged = false;  // the step's own problem stays unsolved: reported
  applyImpulses(ws);
  c.st.frictionless_fallback = true;
  c.st.fallback_kinetic_change = kineticChange(c, k_unsolved);
}

// ---- EnergyCap
bool farOff(const RescueContext& c) {
  return !c.rep.converged && !(c.rep.residual <= kFrictionlessFallbackResidual);
}
// Along the answer's direction, dK(a) = a P.u_free + a^2/2 P.W.P; the a in
// [0, 1] that minimises it, so dK <= 0. Prescribed motions are scaled too.
void capEnergy(RescueContext& c) {
  StepWorkspace& ws = c.ws;
  const int r = ws.rows;
  const auto G = ws.G.topRows(r);
  double pu = 0, pwp = 0;
  for (int i = 0; i < r; ++i) {
    pu += ws.P[i] * G.row(i).dot(ws.vfree);
    pwp += ws.P[i] * G.row(i).dot(ws.vnew - ws.vfree);
  }
  if (!(std::isfinite(pu) && std::isfinite(pwp) && pu + 0.5 * pwp > 1e-12 * kineticEnergyOf(c.m, ws.vfree)))
    return;
  const double a = pwp > 0 ? std::min(1.0, std::max(0.0, -pu / pwp)) : 0.0;
  ws.P.head(r) *= a;
  applyImpulses(ws);
  c.st.energy_capped = true;
}

// The policy, in order: a rescue whose condition holds is applied; the Halving
// row (no action) ends the policy while the step can still be halved.
struct Rescue {
  StepRescue rescue;
  bool (*applies)(const RescueContext&);
  void (*apply)(RescueContext&);
};
constexpr Rescue kRescuePolicy[] = {
    {StepRescue::ColdRetry, answerNotFinite, retryCold},
    {StepRescue::PlasticImpact, impactGainsEnergy, solvePlastic},
    {StepRescue::Halving, stepCanBeHalved, nullptr},
    {StepRescue::LongerSolve, unsolved, solveLonger},
    {StepRescue::PlasticRetry, unsolvedWithRestitution, retryPlastic},
    {StepRescue::Frictionless, farOffOrGainsEnergy, solveFrictionless},
    {StepRescue::EnergyCap, farOff, capEnergy},
};
static_assert(sizeof(kRescuePolicy) / sizeof(kRescuePolicy[0]) == kStepRescueCount, "one row per StepRescue");

constexpr const char* kRescueNames[kStepRescueCount] = {
    "cold_retry", "plastic_impact", "halving", "longer_solve", "plastic_retry", "frictionless", "energy_cap"};

}  // namespace

SolverReport solveWithRescues(const Model& m, StepWorkspace& ws, const SolverOptions& options, bool may_halve,
                              const ResolveObserver& observe, StepStats& st) {
  const int r = ws.rows;
  const auto W = ws.W.topLeftCorner(r, r);
  const auto b = ws.b.head(r);
  RescueContext c{m, ws, st, observe, may_halve, options, SolverReport()};
  if (observe.fn) ws.P_start.head(r) = ws.P.head(r);
  c.rep = ws.solver.solve(W, b, ws.problem, c.options, ws.P.head(r));
  ++st.solves_by_stage[static_cast<int>(c.rep.stage)];
  applyImpulses(ws);
  if (observe.fn)
    (*observe.fn)(ProblemView{observe.t, observe.round, W, b, ws.problem, ws.P_start.head(r), ws.P.head(r), c.rep,
                              observe.halvings, observe.substep});
  for (const Rescue& rescue : kRescuePolicy) {
    if (!rescue.applies(c)) continue;
    if (!rescue.apply) break;
    rescue.apply(c);
  }
  return c.rep;
}

const char* stepRescueName(StepRescue rescue) {
  const int i = static_cast<int>(rescue);
  return i >= 0 && i < kStepRescueCount ? kRescueNames[i] : "?";
}

bool stepTookRescue(const StepStats& st, StepRescue rescue) {
  switch (rescue) {
    case StepRescue::ColdRetry: return st.cold_retry;
    case StepRescue::PlasticImpact: return st.plastic_fallback;
    case StepRescue::Halving: return st.substeps > 1;
    case StepRescue::LongerSolve: return st.longer_solve;
    case StepRescue::PlasticRetry: return st.plastic_retry;
    case StepRescue::Frictionless: return st.frictionless_fallback;
    case StepRescue::EnergyCap: return st.energy_capped;
  }
  return false;
}

}  // namespace nscd
