#include "stage_counts.hpp"

namespace nscd {

void StageCounts::addStep(const StepStats& s) {
  for (int i = 0; i < kSolverStageCount; ++i) solver_stages[i] += s.solves_by_stage[i];
  for (int i = 0; i < kStepRescueCount; ++i) rescues[i] += stepTookRescue(s, static_cast<StepRescue>(i));
}

void StageCounts::add(const StageCounts& other) {
  for (int i = 0; i < kSolverStageCount; ++i) solver_stages[i] += other.solver_stages[i];
  for (int i = 0; i < kStepRescueCount; ++i) rescues[i] += other.rescues[i];
}

std::string StageCounts::jsonFields() const {
  std::string j = "\"solver_stages\":{";
  for (int i = 0; i < kSolverStageCount; ++i)
    j += std::string(i ? "," : "") + "\"" + solverStageName(static_cast<SolverStage>(i)) + "\":" +
         std::to_string(solver_stages[i]);
  j += "},\"rescues\":{";
  for (int i = 0; i < kStepRescueCount; ++i)
    j += std::string(i ? "," : "") + "\"" + stepRescueName(static_cast<StepRescue>(i)) + "\":" +
         std::to_string(rescues[i]);
  return j + "}";
}

}  // namespace nscd
