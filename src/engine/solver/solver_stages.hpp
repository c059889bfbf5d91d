// The stages of the solver's schedule (solver_schedule.cpp), one function each
// (solver_stages.cpp). A stage begins where its table row's start puts the
// iterate, runs within its row's budget, and ends with an outcome; when it is
// Unsolved the stage leaves the iterate where its contract says, for the next
// row's start to take it from there. Internal to the engine.
#pragma once

#include "solve_run.hpp"

namespace nscd {

enum class StageOutcome { Solved, Unsolved, NonFinite };

// Where a stage begins. Every start from a new point offers it to the best
// iterate (run.best).
enum class Start {
  Current,        // the iterate as the last stage left it
  Zero,           // P = 0 (the sweeps' stall watch starts afresh)
  Warm,           // the warm start the solve was given (likewise)
  Best,           // the best iterate, if it is better than the current one
  BestOnCopy,     // the same, on a copy: the stage's work is kept only if it solves
  NewtonStart,    // where the last Newton started (the sweeps go on from there)
  // After the Newton's restarts from zero and the warm start: where the last
  // one started if the restarts improved on the best iterate the sweeps had
  // before them, or if its Newton came no closer than the best; else the best.
  AfterRestarts,
};

// How many NSGS sweeps a sweeping stage runs.
enum class SweepRule {
  UntilNewton,  // until the Newton is expected to be cheaper (after one sweep on small
                // problems and for SolverMethod::Newton), or to the sweep budget
  One,          // one sweep
  ToBudget,     // up to options.max_iterations sweeps in all
};

// A stage's budget: its sweeps; its Newton's (iterations, stall, regularisation:
// the short and long Newtons also share the run's budget of max_iterations, the
// proximal Newton and the cone fixed point have their own); its Newton attempts.
struct StageBudget {
  SweepRule sweeps = SweepRule::One;
  NewtonBudget newton = {0, 0, 0};
  int attempts = 0;
};

// One row of a schedule.
struct Stage {
  SolverStage stage;
  Start start;
  StageBudget budget;
  bool (*when)(const SolveRun&);  // runs only if this holds (null: always)
  StageOutcome (*run)(SolveRun&, const Stage&);
};

// Bilateral rows only: P = -W⁺ b from the factor prepareEqualityProblem made,
// then up to budget.attempts refinements P -= W⁺ U while the error is above
// the tolerance. Unsolved (an inconsistent or ill-conditioned system): the best
// of these iterates.
StageOutcome equalityStage(SolveRun& run, const Stage& stage);
// NSGS by the budget's rule; Unsolved: the last sweep's iterate, and under
// UntilNewton the run handed to the Newton (run.newtonDue) unless the sweep
// budget ran out.
StageOutcome sweepStage(SolveRun& run, const Stage& stage);
// One short Newton; Unsolved: back where it started.
StageOutcome newtonStage(SolveRun& run, const Stage& stage);
// One sweep from the start, then a short Newton; Unsolved: where the Newton stopped.
StageOutcome newtonRestartStage(SolveRun& run, const Stage& stage);
// Up to budget.attempts times: one sweep, then a short Newton, back where it
// started when it fails, but for the last attempt, whose iterate stays
// (run.lastAttemptFailed). Stops when the sweep budget runs out.
StageOutcome newtonRetryStage(SolveRun& run, const Stage& stage);
// The proximal Newton on a copy of the iterate (Start::BestOnCopy): the run
// takes its answer if it solves, else it is as it was (U recomputed).
StageOutcome proximalTrialStage(SolveRun& run, const Stage& stage);
// The proximal Newton; Unsolved: its answer, which becomes the best.
StageOutcome proximalStage(SolveRun& run, const Stage& stage);
// A long Newton; Unsolved: the best iterate if it is better than the Newton's
// last, else the Newton's last.
StageOutcome longNewtonStage(SolveRun& run, const Stage& stage);
// The cone fixed point; Unsolved: its answer, which becomes the best.
StageOutcome coneStage(SolveRun& run, const Stage& stage);

// Puts the iterate where `start` says (but BestOnCopy: the stage's own).
void beginStage(SolveRun& run, Start start);

}  // namespace nscd
