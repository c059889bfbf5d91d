// Stage 8: step halving. A step whose friction-contact problem the solver leaves
// unsolved is taken again from its start as two steps of h/2, each halved again
// while unsolved (Simulator::step, Settings::max_step_halvings): the Halving row
// of the rescue policy (rescue_policy.cpp), whose later rescues wait for the
// smallest step. Once a substep of that smallest length stays unsolved, the rest
// of the step is taken in the substeps already begun without halving them
// (Simulator::takeHalves): a step no solve settles takes 2 L + 1 attempts, not
// 2^(L+1) - 1 (a step that halving does settle may still take up to the latter).
// Why: within one step a light link can cross a tight bearing, so that contacts
// on both sides of it enter one problem with Newton's law on each; such a problem
// may have no solution at all (stress case 939: not strictly feasible, and no
// Siconos solver solves them either), while in h/2 or h/4 the link meets one side
// at a time. The attempt a halving drops leaves the State as it found it
// (Simulator::advance). Here: the substeps' stats and outputs gathered into the step's.
#include <algorithm>
#include <cmath>

#include "step_stages.hpp"

namespace nscd {
namespace {

// The larger in magnitude: a kinetic change of some substep stands for the step.
double largerChange(double a, double b) { return std::abs(b) > std::abs(a) ? b : a; }

}  // namespace

void addDroppedAttempt(const StepStats& attempt, StepStats& total) {
  total.iterations += attempt.iterations;
  for (int s = 0; s < kSolverStageCount; ++s) total.solves_by_stage[s] += attempt.solves_by_stage[s];
  total.direct_equality_solves += attempt.direct_equality_solves;
}

void startHalvedStep(const StepStats& attempt, StepStats& total, StepOutputs& acc) {
  total = StepStats();
  total.substeps = 0;
  addDroppedAttempt(attempt, total);
  std::fill(acc.actuator_effort.begin(), acc.actuator_effort.end(), 0.0);
  std::fill(acc.pair_fn.begin(), acc.pair_fn.end(), 0.0);
  std::fill(acc.pair_ft_vec.begin(), acc.pair_ft_vec.end(), Vec3::Zero());
  std::fill(acc.cj_fn.begin(), acc.cj_fn.end(), 0.0);
}

void addSubstep(const StepStats& sub, int level, const StepOutputs& out, StepStats& total,
                StepOutputs& acc) {
  total.iterations += sub.iterations;
  for (int s = 0; s < kSolverStageCount; ++s) total.solves_by_stage[s] += sub.solves_by_stage[s];
  total.direct_equality_solves += sub.direct_equality_solves;
  if (!(sub.residual <= total.residual)) total.residual = sub.residual;  // NaN stays
  total.converged = total.converged && sub.converged;
  total.active_contacts = sub.active_contacts;
  total.rows = sub.rows;
  total.projection_passes += sub.projection_passes;
  total.projection_least_distance += sub.projection_least_distance;
  total.cold_retry = total.cold_retry || sub.cold_retry;
  total.plastic_fallback = total.plastic_fallback || sub.plastic_fallback;
  total.late_contacts += sub.late_contacts;
  total.plastic_retry = total.plastic_retry || sub.plastic_retry;
  total.longer_solve = total.longer_solve || sub.longer_solve;
  total.plastic_retry_kinetic_change =
      largerChange(total.plastic_retry_kinetic_change, sub.plastic_retry_kinetic_change);
  total.frictionless_fallback = total.frictionless_fallback || sub.frictionless_fallback;
  total.fallback_kinetic_change = largerChange(total.fallback_kinetic_change, sub.fallback_kinetic_change);
  total.energy_capped = total.energy_capped || sub.energy_capped;
  total.projection_energy_removed += sub.projection_energy_removed;
  total.iteration_matrix_fallback = total.iteration_matrix_fallback || sub.iteration_matrix_fallback;
  total.substeps += 1;
  total.halvings = std::max(total.halvings, level);

  // Forces are impulse / length: the substep's share of the step's impulse.
  const double fraction = std::ldexp(1.0, -level);
  for (size_t i = 0; i < acc.actuator_effort.size(); ++i)
    acc.actuator_effort[i] += fraction * out.actuator_effort[i];
  for (size_t p = 0; p < acc.pair_fn.size(); ++p) {
    acc.pair_fn[p] += fraction * out.pair_fn[p];
    acc.pair_ft_vec[p] += fraction * out.pair_ft_vec[p];
  }
  for (size_t c = 0; c < acc.cj_fn.size(); ++c) acc.cj_fn[c] += fraction * out.cj_fn[c];
}

void finishHalvedStep(const StepStats& total, const StepOutputs& acc, StepOutputs& out) {
  const double penetration = out.stats.max_penetration;  // at the end of the step
  out.stats = total;
  out.stats.max_penetration = penetration;
  out.actuator_effort = acc.actuator_effort;
  out.pair_fn = acc.pair_fn;
  out.pair_ft_vec = acc.pair_ft_vec;
  for (size_t p = 0; p < out.pair_ft.size(); ++p) out.pair_ft[p] = out.pair_ft_vec[p].norm();
  out.cj_fn = acc.cj_fn;
}

}  // namespace nscd
