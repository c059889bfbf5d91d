// Stage 4c: safeguards on the solved impulses, each counted in StepStats.
// - Newton's impact law at several coupled frictional points can add kinetic
//   energy (it is only proven dissipative for one point), and with theta = 1/2
//   the impulses can do positive work over the step: the impact is then taken
//   plastic (e = 0).
// - A problem left unsolved at the smallest step is solved again from its answer
//   with 10 times the budget (StepStats::longer_solve): the physics unchanged.
// - A problem with restitution left unsolved: Newton's law at coupled points may
//   have no solution (a link bounced off one contact into another within the
//   step, which no velocity can meet) where the plastic law has one. The problem
//   is solved again with e = 0, friction kept; if that converges it is the step's
//   answer (a plastic retry), else the unsolved answer stays.
// - A problem left unsolved whose answer adds kinetic energy through the contacts,
//   or far from solved (residual > 1e-3; it may have no solution: Coulomb friction
//   at coupled points), can pump energy into the mechanism or drive bodies through
//   each other: the step is taken frictionless and plastic, a convex problem.
//   (An exact answer with e = 0 never adds energy through its contacts; an
//   unsolved one did, 0.6 J per step, in a C-60 trip at half the axial play.)
// - Still far from solved: the impulses are scaled so they add no kinetic energy.
// These last four run only at the smallest step, and the last three change the
// physics: while the step can still be halved (Settings::max_step_halvings) an
// unsolved problem is left as it is, and the step is taken again as two of h/2
// (step_halving.cpp).
#include <algorithm>
#include <cmath>

#include "step_stages.hpp"

namespace nscd {
namespace {

// The budget of the last solve before the fallbacks, in multiples of the run's.
constexpr int kLongerBudget = 10;
// Residual above which an unconverged frictional answer is replaced.
constexpr double kFrictionlessFallbackResidual = 1e-3;
// Kinetic energy (relative to K(v_free)) an unsolved answer may add through its
// contacts before it is replaced: above round-off, far below a real gain.
constexpr double kUnsolvedEnergyGain = 1e-9;

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

bool impactGainsEnergy(const Model& m, const StepWorkspace& ws) {
  return anyRestitution(ws) && impulsesGainEnergy(m, ws, 1e-12, true);
}

}  // namespace

void applyImpactSafeguards(const Model& m, StepWorkspace& ws, const SolverOptions& options,
                           SolverReport& rep, StepStats& st, bool last_resort,
                           const ResolveObserver& observe) {
  const int r = ws.rows;
  const auto W = ws.W.topLeftCorner(r, r);
  const auto b = ws.b.head(r);
  // The step's problem as it now stands (b and mu as the safeguard set them),
  // solved again from the current answer.
  const auto solveAgain = [&](const char* kind, const SolverOptions& with) {
    if (observe.fn) ws.P_start.head(r) = ws.P.head(r);
    const SolverReport again = ws.solver.solve(W, b, ws.problem, with, ws.P.head(r));
    if (observe.fn)
      (*observe.fn)(ProblemView{observe.t, observe.round, W, b, ws.problem, ws.P_start.head(r),
                                ws.P.head(r), again, observe.halvings, observe.substep, kind});
    return again;
  };
  bool plastic = false;
  if (st.active_contacts > 0 && impactGainsEnergy(m, ws)) {
    removeRestitution(ws);
    rep = solveAgain("plastic", options);
    applyImpulses(ws);
    plastic = st.plastic_fallback = true;
  }
  if (!last_resort) return;
  // Before anything that changes the physics, the same problem again from the
  // answer so far, with kLongerBudget times the budget: the few strictly
  // feasible problems the smallest step still leaves (jammed sets with impulses
  // 100 times the usual) need 1 000 to 1 500 Newton iterations. The better of
  // the two answers stays.
  if (!rep.converged && st.active_contacts > 0) {
    ws.retry_P.head(r) = ws.P.head(r);
    SolverOptions longer = options;
    longer.max_iterations = options.max_iterations * kLongerBudget;
    const SolverReport rep_l = solveAgain("longer", longer);
    rep.iterations += rep_l.iterations;
    if (rep_l.converged || rep_l.residual < rep.residual) {
      rep.residual = rep_l.residual;
      rep.converged = rep_l.converged;
      applyImpulses(ws);
      st.longer_solve = true;
    } else {
      ws.P.head(r) = ws.retry_P.head(r);
    }
  }
  if (!rep.converged && !plastic && st.active_contacts > 0 && anyRestitution(ws)) {
    ws.retry_P.head(r) = ws.P.head(r);
    ws.retry_b.head(r) = b;
    const double k_unsolved = kineticEnergyOf(m, ws.vnew);
    removeRestitution(ws);
    const SolverReport rep_p = solveAgain("plastic_retry", options);
    rep.iterations += rep_p.iterations;
    if (rep_p.converged) {
      rep.residual = rep_p.residual;
      rep.converged = true;
      applyImpulses(ws);
      plastic = st.plastic_retry = true;
      st.plastic_retry_kinetic_change =
          (kineticEnergyOf(m, ws.vnew) - k_unsolved) / (kineticEnergyOf(m, ws.vfree) + 1e-300);
    } else {
      ws.P.head(r) = ws.retry_P.head(r);
      ws.b.head(r) = ws.retry_b.head(r);
    }
  }
  if (!rep.converged && st.active_contacts > 0 &&
      (!(rep.residual <= kFrictionlessFallbackResidual) || impulsesGainEnergy(m, ws, kUnsolvedEnergyGain, false))) {
    // Frictionless and plastic; the problem blocks are rebuilt by the next assembly.
    const double k_unsolved = kineticEnergyOf(m, ws.vnew);
    if (!plastic) removeRestitution(ws);
    for (ProblemBlock& pb : ws.problem) pb.mu = 0;
    const SolverReport rep0 = solveAgain("frictionless", options);
    if (ws.P.head(r).allFinite()) {
      rep.iterations += rep0.iterations;
      rep.residual = rep0.residual;
      rep.converged = false;  // the step's own problem stays unsolved: reported
      applyImpulses(ws);
      st.frictionless_fallback = true;
      st.fallback_kinetic_change =
          (kineticEnergyOf(m, ws.vnew) - k_unsolved) / (kineticEnergyOf(m, ws.vfree) + 1e-300);
    }
  }
  if (!rep.converged && !(rep.residual <= kFrictionlessFallbackResidual)) {
    // Along the answer's direction, dK(a) = a P.u_free + a^2/2 P.W.P; take the a
    // in [0, 1] that minimises it, so dK <= 0. Prescribed motions are scaled too.
    const auto G = ws.G.topRows(r);
    double pu = 0, pwp = 0;
    for (int i = 0; i < r; ++i) {
      pu += ws.P[i] * G.row(i).dot(ws.vfree);
      pwp += ws.P[i] * G.row(i).dot(ws.vnew - ws.vfree);
    }
    if (std::isfinite(pu) && std::isfinite(pwp) &&
        pu + 0.5 * pwp > 1e-12 * kineticEnergyOf(m, ws.vfree)) {
      const double a = pwp > 0 ? std::min(1.0, std::max(0.0, -pu / pwp)) : 0.0;
      ws.P.head(r) *= a;
      applyImpulses(ws);
      st.energy_capped = true;
    }
  }
}

}  // namespace nscd
