#include "run_summary.hpp"

#include <cmath>
#include <cstdio>

namespace nscd {

namespace {

std::string jsonNumber(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

}  // namespace

std::string runSummaryJson(const RunSummary& r) {
  return "{\"steps\":" + std::to_string(r.steps) + ",\"sim_time\":" + jsonNumber(r.sim_time) +
         ",\"wall_s\":" + jsonNumber(r.wall_s) +
         ",\"rtf\":" + jsonNumber(r.wall_s > 0 ? r.sim_time / r.wall_s : 0.0) +
         ",\"iters_mean\":" + jsonNumber(r.steps > 0 ? double(r.iters_sum) / r.steps : 0.0) +
         ",\"iters_max\":" + std::to_string(r.iters_max) +
         ",\"residual_max\":" + jsonNumber(r.residual_max) +
         ",\"unconverged_steps\":" + std::to_string(r.unconverged_steps) +
         ",\"halved_steps\":" + std::to_string(r.halved_steps) +
         ",\"substeps_max\":" + std::to_string(r.substeps_max) +
         ",\"longer_solves\":" + std::to_string(r.longer_solves) +
         ",\"plastic_retries\":" + std::to_string(r.plastic_retries) +
         ",\"frictionless_fallbacks\":" + std::to_string(r.frictionless_fallbacks) +
         ",\"energy_capped_steps\":" + std::to_string(r.energy_capped_steps) +
         ",\"max_penetration\":" + jsonNumber(r.max_penetration) +
         ",\"energy_initial\":" + jsonNumber(r.energy_initial) +
         ",\"energy_final\":" + jsonNumber(r.energy_final) +
         ",\"rejected_steps\":" + std::to_string(r.rejected_steps) +
         ",\"extrapolated_steps\":" + std::to_string(r.extrapolated_steps) +
         ",\"h_min\":" + jsonNumber(r.h_min) + ",\"h_max\":" + jsonNumber(r.h_max) + "," +
         r.counts.jsonFields() + "}";
}

}  // namespace nscd
