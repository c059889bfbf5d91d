// The metric columns shared by nscd_sweep and nscd_stress CSVs.
#pragma once

#include <cstdio>
#include <string>

#include "run_case.hpp"

namespace nscd::sweep {

// Round-trip formatting: reruns compare byte for byte.
inline std::string fmt(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// A CSV cell without separators or line breaks.
inline std::string cell(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n' || c == '\r' || c == '"') c = ';';
  return s;
}

inline std::string metricsHeader(bool timing) {
  return std::string("status,steps,sim_time,") + (timing ? "wall_s," : "") +
         "iters_mean,iters_max,residual_max,unconverged_steps,unconverged_residual_max,"
         "max_penetration,max_violation,clearance_min,energy_initial,energy_final,"
         "energy_gain_max,energy_step_gain_max,kinetic_peak";
}

inline std::string metricsRow(const CaseMetrics& r, bool timing) {
  std::string s = cell(r.status) + "," + std::to_string(r.steps) + "," + fmt(r.sim_time) + ",";
  if (timing) s += fmt(r.wall_s) + ",";
  s += fmt(r.iters_mean) + "," + std::to_string(r.iters_max) + "," + fmt(r.residual_max) + "," +
       std::to_string(r.unconverged_steps) + "," + fmt(r.unconverged_residual_max) + "," +
       fmt(r.max_penetration) + "," + fmt(r.max_violation) + "," + fmt(r.clearance_min) + "," +
       fmt(r.energy_initial) + "," + fmt(r.energy_final) + "," + fmt(r.energy_gain_max) + "," +
       fmt(r.energy_step_gain_max) + "," + fmt(r.kinetic_peak);
  return s;
}

}  // namespace nscd::sweep
