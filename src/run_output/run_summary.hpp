// The one-line JSON summary nscd_run prints on standard output after a run
// (docs/interfaces.md); nscd_sweep --series writes the same line per run.
#pragma once

#include <string>

#include "stage_counts.hpp"

namespace nscd {

struct RunSummary {
  long steps = 0;  // steps done
  double sim_time = 0;
  double wall_s = 0;
  long iters_sum = 0;
  int iters_max = 0;
  double residual_max = 0;
  long unconverged_steps = 0;
  long halved_steps = 0;  // steps taken again in halves (Settings::max_step_halvings)
  int substeps_max = 1;   // the most substeps one step took
  long longer_solves = 0;  // steps whose last solve took 10 times the budget (StepStats::longer_solve)
  long plastic_retries = 0;
  long frictionless_fallbacks = 0;
  long energy_capped_steps = 0;
  double max_penetration = 0;
  double energy_initial = 0;
  double energy_final = 0;
  // Step control (Settings::step_control): steps rejected before a step was kept
  // (adaptive), steps whose answer was extrapolated (adaptive), the shortest and
  // longest step kept, s (fixed: dt both).
  long rejected_steps = 0;
  long extrapolated_steps = 0;
  double h_min = 0;
  double h_max = 0;
  StageCounts counts;  // solves per solver stage, steps per rescue
};

// {"steps":..,"sim_time":..,"wall_s":..,"rtf":..,"iters_mean":..,...,"solver_stages":{..},
// "rescues":{..}} without a line break; numbers as %.10g, non-finite ones as null.
std::string runSummaryJson(const RunSummary& r);

}  // namespace nscd
