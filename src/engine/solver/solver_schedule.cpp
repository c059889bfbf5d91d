// The solver's schedule as data: per SolverMethod, the stages a solve runs in
// order until one meets the tolerance (solver_stages.hpp: each stage's
// contract; docs/solver.md: what each is for and how many solves it finishes).
#include "solver_schedule.hpp"

#include <iterator>

#include "solver_stages.hpp"

namespace nscd {
namespace {

// The short Newton attempts: iterations, without halving the error, delta.
constexpr NewtonBudget kShortNewton{60, 25, 1e-10};
// The long Newton after everything else. Some frictional sets converge only
// after a few hundred Newton steps whose error does not halve every 25: too
// slow to try on every hard solve, where the sweeps and short attempts usually
// win, but better than returning unconverged. Its Jacobian regularisation floor
// is 100x the short attempts': over hundreds of steps on a hyperstatic set, the
// bare Newton step's components along W's near-null directions (impulse moved
// between redundant contacts) throw the iterate across kinks and it cycles.
constexpr NewtonBudget kLongNewton{500, 150, 1e-8};
// Newton attempts between sweeps after the first and its two restarts.
constexpr int kNewtonRetries = 3;

bool newtonDue(const SolveRun& run) { return run.newtonDue; }
// The warm start as a third start when the first Newton began many sweeps away
// from it (then the sweeps had carried the iterate somewhere else), and not zero.
bool warmRestartDue(const SolveRun& run) {
  return run.newtonDue && run.sweepsAtHandover > 1 &&
         run.problem.buf.Pinitial.head(run.problem.m).cwiseAbs().maxCoeff() > 0;
}
bool lastAttemptFailed(const SolveRun& run) { return run.lastAttemptFailed; }
bool sweepsLeft(const SolveRun& run) { return run.rep.sweeps < run.options.max_iterations; }
bool coneApplies(const SolveRun& run) { return coneFixedPointApplies(run); }

using S = SolverStage;
constexpr StageBudget kNoBudget{};
// Refinements of the direct solve (each one more solve with the factor).
constexpr int kEqualityRefinements = 2;

// Bilateral rows only (chosen by the problem's content, whatever the method):
// a linear system, which one factorisation solves.
constexpr Stage kEqualitySchedule[] = {
    {S::Equalities,      Start::Current,       {SweepRule::One, {0, 0, 0}, kEqualityRefinements}, nullptr,         equalityStage},
};

// Auto and Newton: the sweeps, the Newton when it is expected to be cheaper, and
// for what they leave unsolved the proximal Newton, a long Newton and the cone
// fixed point.
constexpr Stage kNewtonSchedule[] = {
    // stage             start                 budget                                           when               run
    {S::Sweeps,          Start::Current,       {SweepRule::UntilNewton, {0, 0, 0}, 0},          nullptr,           sweepStage},
    {S::Newton,          Start::Current,       {SweepRule::One, kShortNewton, 1},               newtonDue,         newtonStage},
    {S::NewtonFromZero,  Start::Zero,          {SweepRule::One, kShortNewton, 1},               newtonDue,         newtonRestartStage},
    {S::NewtonFromWarm,  Start::Warm,          {SweepRule::One, kShortNewton, 1},               warmRestartDue,    newtonRestartStage},
    {S::NewtonRetry,     Start::AfterRestarts, {SweepRule::One, kShortNewton, kNewtonRetries},  newtonDue,         newtonRetryStage},
    {S::ProximalTrial,   Start::BestOnCopy,    kNoBudget,                                       lastAttemptFailed, proximalTrialStage},
    {S::SweepsToBudget,  Start::NewtonStart,   {SweepRule::ToBudget, {0, 0, 0}, 0},             sweepsLeft,        sweepStage},
    {S::ProximalNewton,  Start::Best,          kNoBudget,                                       nullptr,           proximalStage},
    {S::LongNewton,      Start::Zero,          {SweepRule::One, kLongNewton, 1},                nullptr,           longNewtonStage},
    {S::ConeFixedPoint,  Start::Best,          kNoBudget,                                       coneApplies,       coneStage},
};

// NSGS (and problems too large for a dense Newton): sweeps alone.
constexpr Stage kNsgsSchedule[] = {
    {S::Sweeps,          Start::Current,       {SweepRule::ToBudget, {0, 0, 0}, 0},             nullptr,           sweepStage},
};

// ProximalNewton (solver studies): one sweep, the proximal Newton at once, then
// as the others end.
constexpr Stage kProximalSchedule[] = {
    {S::Sweeps,          Start::Current,       {SweepRule::One, {0, 0, 0}, 0},                  nullptr,           sweepStage},
    {S::ProximalNewton,  Start::Current,       kNoBudget,                                       nullptr,           proximalStage},
    {S::SweepsToBudget,  Start::Current,       {SweepRule::ToBudget, {0, 0, 0}, 0},             sweepsLeft,        sweepStage},
    {S::ProximalNewton,  Start::Best,          kNoBudget,                                       nullptr,           proximalStage},
    {S::LongNewton,      Start::Zero,          {SweepRule::One, kLongNewton, 1},                nullptr,           longNewtonStage},
    {S::ConeFixedPoint,  Start::Best,          kNoBudget,                                       coneApplies,       coneStage},
};

struct Schedule {
  const Stage* begin;
  const Stage* end;
};

Schedule scheduleFor(const SolveRun& run) {
  const SolverMethod method = run.options.method;
  const int m = run.problem.m;
  if (run.problem.equalityOnly) return {std::begin(kEqualitySchedule), std::end(kEqualitySchedule)};
  if (method == SolverMethod::NSGS || m > kNewtonMaxRows) return {std::begin(kNsgsSchedule), std::end(kNsgsSchedule)};
  if (method == SolverMethod::ProximalNewton) return {std::begin(kProximalSchedule), std::end(kProximalSchedule)};
  return {std::begin(kNewtonSchedule), std::end(kNewtonSchedule)};
}

}  // namespace

bool scheduleUsesNewton(SolverMethod method, int m) {
  return method != SolverMethod::NSGS && m <= kNewtonMaxRows;
}

bool solveBySchedule(SolveRun& run) {
  const Schedule schedule = scheduleFor(run);
  for (const Stage* stage = schedule.begin; stage != schedule.end; ++stage) {
    if ((run.options.skip_stages >> static_cast<int>(stage->stage) & 1) || (stage->when && !stage->when(run)))
      continue;
    beginStage(run, stage->start);
    switch (stage->run(run, *stage)) {
      case StageOutcome::Solved:
        run.rep.stage = stage->stage;
        return true;
      case StageOutcome::NonFinite:
        return false;
      case StageOutcome::Unsolved:
        break;
    }
  }
  run.rep.stage = SolverStage::Unsolved;
  return true;
}

}  // namespace nscd
