// The solver's schedule (solver_schedule.cpp): the stages a solve runs, in
// order, for its SolverMethod and size. Internal to the engine.
#pragma once

#include "solve_run.hpp"

namespace nscd {

constexpr int kNewtonMaxRows = 400;  // dense m x m LU beyond this costs more than sweeps

// Whether the schedule for this method and problem size has Newton stages (their
// buffers, m x m, are then needed).
bool scheduleUsesNewton(SolverMethod method, int m);

// Runs the schedule on a run set up at its warm start (not solved already).
// run.rep.stage: the stage that solved it, or Unsolved (run.it is the last
// stage's iterate; the best is in run.best). False on a non-finite iterate.
bool solveBySchedule(SolveRun& run);

}  // namespace nscd
