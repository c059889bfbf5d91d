// How many solves each stage of the solver's schedule finished and how many steps
// took each rescue, over a run (nscd_run's summary, nscd_stress's, nscd_sweep
// --series'): docs/solver.md, docs/interfaces.md.
#pragma once

#include <array>
#include <string>

#include "nscd_sim/simulator.hpp"

namespace nscd {

struct StageCounts {
  std::array<long, kSolverStageCount> solver_stages{};  // solves finished, per SolverStage
  std::array<long, kStepRescueCount> rescues{};        // steps that took it, per StepRescue

  void addStep(const StepStats& s);
  void add(const StageCounts& other);
  // "solver_stages":{"no_rows":N,...},"rescues":{"cold_retry":N,...} (every name, in enum order).
  std::string jsonFields() const;
};

}  // namespace nscd
