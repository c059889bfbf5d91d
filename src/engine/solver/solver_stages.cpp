// The stages of the solver's schedule (solver_stages.hpp states each one's
// contract; solver_schedule.cpp lists them in order) and their starts.
#include "solver_stages.hpp"

#include <algorithm>
#include <cmath>

namespace nscd {
namespace {

constexpr int kNewtonSmallRows = 24;     // UntilNewton: the Newton after one sweep up to this size
constexpr double kNewtonCostIterations = 6;  // UntilNewton: expected Newton iterations...
// ...each costing (1 + m / this) sweeps: a Newton iteration cost 1.9 sweeps on C-60
// problems of 49-67 rows and 5.6 on box stacks of 252 rows (docs/solver.md).
constexpr double kLuRowsPerSweep = 55;

// A fresh start at the iterate just set: restarted, offered as the best, the
// sweeps' stall watch from here.
void restartFresh(SolveRun& run) {
  restartIterate(run.problem, run.it);
  run.best.offer(run.it);
  run.nsgs = NsgsState::fresh(run.it.err);
}

// To the best iterate, restarted (P = 0 on the zero rows), which stays the best.
void restartAtBest(SolveRun& run) {
  run.it.P.head(run.problem.m) = run.best.P;
  restartIterate(run.problem, run.it);
  run.best.adopt(run.it);
  run.nsgs = NsgsState::fresh(run.it.err);
}

// Back to where the last Newton started: U and the error exact, the sweeps'
// stall watch from here (their proximal weight kept).
void resumeAtNewtonStart(SolveRun& run) {
  run.it.P.head(run.problem.m) = run.problem.buf.Pstart.head(run.problem.m);
  refreshIterate(run.problem, run.it);
  run.nsgs.stallErr = run.it.err;
  run.nsgs.stallIt = run.rep.sweeps;
}

// A Newton from the iterate on the run's Newton budget (what max_iterations
// leaves of it); its start kept in buf.Pstart. True if it converged.
bool newtonAttempt(SolveRun& run, const NewtonBudget& budget) {
  run.problem.buf.Pstart.head(run.problem.m) = run.it.P.head(run.problem.m);
  const int cap = std::min(budget.max_iterations, run.options.max_iterations - run.newtonBudgetUsed);
  const NewtonResult r = runNewton(run.problem, run.it, {cap, budget.stall, budget.delta0});
  run.newtonBudgetUsed += r.iterations;
  run.rep.newton_iterations += r.iterations;
  run.rep.converged = r.converged;
  return r.converged;
}

void handToNewton(SolveRun& run) {
  run.newtonDue = true;
  run.sweepsAtHandover = run.rep.sweeps;
}

// Sweeps in batches up to 1, 2, 4, 8 ... in all until the rate measured over the
// last batch predicts more sweeps to the tolerance than the Newton costs, or a
// batch gains less (in log error) than the one before it, half as long: the
// sweeps are stalling. The rate cannot see a stall coming, and on hyperstatic
// sets the sweeps that run into one move the iterate along W's near-null
// directions, a worse start for the Newton.
StageOutcome sweepUntilNewton(SolveRun& run) {
  const int max = run.options.max_iterations;
  SolverReport& rep = run.rep;
  const double newtonCost = kNewtonCostIterations * (1 + run.problem.m / kLuRowsPerSweep);
  int check = 1;
  double errRef = run.it.err;
  int itRef = rep.sweeps;
  double lastGain = INFINITY;
  while (rep.sweeps < max) {
    if (!runNsgs(run, std::min(check, max))) return StageOutcome::NonFinite;
    if (rep.converged) return StageOutcome::Solved;
    if (rep.sweeps >= max) break;
    const double rate = std::pow(run.it.err / errRef, 1.0 / (rep.sweeps - itRef));
    const double remaining = rate < 1 ? std::log(run.problem.tolerance / run.it.err) / std::log(rate) : INFINITY;
    const double gain = std::log(errRef / run.it.err);
    if (remaining > newtonCost || (std::isfinite(lastGain) && gain < lastGain)) {
      handToNewton(run);
      return StageOutcome::Unsolved;
    }
    errRef = run.it.err;
    itRef = rep.sweeps;
    lastGain = gain;
    check *= 2;
  }
  return StageOutcome::Unsolved;
}

// U = W P + b and the error, for the direct solve: the columns of the nonzero
// P_j added in turn (plain loops: Eigen's general product costs more than the
// sums on problems of 5 to 20 rows).
void equalityResidual(const SolveProblem& pr, Iterate& it) {
  const int m = pr.m;
  double* U = it.U.data();
  for (int i = 0; i < m; ++i) U[i] = pr.b(i);
  for (int j = 0; j < m; ++j) {
    const double pj = it.P(j);
    if (pj == 0) continue;
    const double* wj = pr.W.data() + j * pr.W.outerStride();
    for (int i = 0; i < m; ++i) U[i] += wj[i] * pj;
  }
  it.err = errorFromU(pr.blocks, it.P.data(), U, pr.bnorm);
}

}  // namespace

void beginStage(SolveRun& run, Start start) {
  const int m = run.problem.m;
  switch (start) {
    case Start::Current:
    case Start::BestOnCopy:
      return;
    case Start::Zero:
      run.it.P.head(m).setZero();
      return restartFresh(run);
    case Start::Warm:
      run.it.P.head(m) = run.problem.buf.Pinitial.head(m);
      return restartFresh(run);
    case Start::Best:
      if (run.best.err < run.it.err) restartAtBest(run);
      return;
    case Start::NewtonStart:
      return resumeAtNewtonStart(run);
    case Start::AfterRestarts:
      if (run.best.err < run.bestBeforeRestarts || run.best.err >= run.it.err) return resumeAtNewtonStart(run);
      restartAtBest(run);
      run.nsgs.stallIt = run.rep.sweeps;
      return;
  }
}

StageOutcome equalityStage(SolveRun& run, const Stage& stage) {
  const SolveProblem& pr = run.problem;
  const int m = pr.m;
  Iterate& it = run.it;
  SolverReport& rep = run.rep;
  solveByEqualityFactor(pr.buf, m, pr.b.data(), it.P.data());
  equalityResidual(pr, it);
  run.best.adopt(it);
  rep.sweeps = 1;
  // Refinement: the correction of the residual U (U = 0 is the answer).
  double* correction = pr.buf.d.data();
  for (int k = 0; k < stage.budget.attempts && !(it.err <= pr.tolerance); ++k) {
    solveByEqualityFactor(pr.buf, m, it.U.data(), correction);
    for (int i = 0; i < m; ++i) it.P(i) += correction[i];
    equalityResidual(pr, it);
    run.best.offer(it);
    ++rep.sweeps;
  }
  if (!it.P.head(m).allFinite() || !std::isfinite(it.err)) return StageOutcome::NonFinite;
  rep.converged = it.err <= pr.tolerance;
  return rep.converged ? StageOutcome::Solved : StageOutcome::Unsolved;
}

StageOutcome sweepStage(SolveRun& run, const Stage& stage) {
  const bool small = run.problem.m <= kNewtonSmallRows || run.options.method == SolverMethod::Newton;
  if (stage.budget.sweeps == SweepRule::UntilNewton && !small) return sweepUntilNewton(run);
  const int until = stage.budget.sweeps == SweepRule::ToBudget ? run.options.max_iterations : run.rep.sweeps + 1;
  if (!runNsgs(run, until)) return StageOutcome::NonFinite;
  if (run.rep.converged) return StageOutcome::Solved;
  if (stage.budget.sweeps == SweepRule::UntilNewton) handToNewton(run);
  return StageOutcome::Unsolved;
}

StageOutcome newtonStage(SolveRun& run, const Stage& stage) {
  if (newtonAttempt(run, stage.budget.newton)) return StageOutcome::Solved;
  resumeAtNewtonStart(run);
  run.bestBeforeRestarts = run.best.err;
  return StageOutcome::Unsolved;
}

StageOutcome newtonRestartStage(SolveRun& run, const Stage& stage) {
  if (!runNsgs(run, run.rep.sweeps + 1)) return StageOutcome::NonFinite;
  if (run.rep.converged) return StageOutcome::Solved;
  return newtonAttempt(run, stage.budget.newton) ? StageOutcome::Solved : StageOutcome::Unsolved;
}

StageOutcome newtonRetryStage(SolveRun& run, const Stage& stage) {
  const int max = run.options.max_iterations;
  SolverReport& rep = run.rep;
  for (int attempt = 1; attempt <= stage.budget.attempts && rep.sweeps < max; ++attempt) {
    if (!runNsgs(run, std::min(rep.sweeps + 1, max))) return StageOutcome::NonFinite;
    if (rep.converged) return StageOutcome::Solved;
    if (rep.sweeps >= max) break;
    if (newtonAttempt(run, stage.budget.newton)) return StageOutcome::Solved;
    if (attempt < stage.budget.attempts) resumeAtNewtonStart(run);
    else run.lastAttemptFailed = true;
  }
  return StageOutcome::Unsolved;
}

StageOutcome proximalTrialStage(SolveRun& run, const Stage&) {
  const SolveProblem& pr = run.problem;
  const int m = pr.m;
  Iterate copy(pr.buf.Ptrial.head(m), pr.buf.U, m);
  if (run.best.err < run.it.err) {
    copy.P.head(m) = run.best.P;
    restartIterate(pr, copy);
  } else {
    copy.P.head(m) = run.it.P.head(m);
    copy.err = run.it.err;
  }
  if (runProximalNewton(run, copy)) {
    run.it.P.head(m) = copy.P.head(m);  // U is the copy's already (the same buffer)
    run.it.err = copy.err;
    run.rep.converged = true;
    return StageOutcome::Solved;
  }
  refreshIterate(pr, run.it);
  return StageOutcome::Unsolved;
}

StageOutcome proximalStage(SolveRun& run, const Stage&) {
  if (runProximalNewton(run, run.it)) {
    run.rep.converged = true;
    return StageOutcome::Solved;
  }
  run.best.adopt(run.it);
  run.nsgs = NsgsState::fresh(run.it.err);
  return StageOutcome::Unsolved;
}

StageOutcome longNewtonStage(SolveRun& run, const Stage& stage) {
  if (newtonAttempt(run, stage.budget.newton)) return StageOutcome::Solved;
  if (run.best.err < run.it.err) restartAtBest(run);
  return StageOutcome::Unsolved;
}

StageOutcome coneStage(SolveRun& run, const Stage&) {
  if (runConeFixedPoint(run)) {
    run.rep.converged = true;
    return StageOutcome::Solved;
  }
  run.best.adopt(run.it);
  run.nsgs = NsgsState::fresh(run.it.err);
  return StageOutcome::Unsolved;
}

}  // namespace nscd
