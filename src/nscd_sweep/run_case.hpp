// One headless run of a model for the performance tools (sweep, stress,
// work-precision): steps it, watches for failure and collects the figures.
#pragma once

#include <string>
#include <vector>

#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/model.hpp"
#include "nscd_sim/simulator.hpp"
#include "stage_counts.hpp"

namespace nscd::sweep {

struct CaseOptions {
  double duration = 0.1;          // simulated time, s (rounded to whole steps)
  // If set, the run starts from this state (nscd_run --initial-state: its time,
  // poses, velocities, warm starts and commands; the schedules continue from its
  // time; sim_time counts from it). Not owned; read by concurrent runs.
  const State* initial_state = nullptr;
  // Call Simulator::constraintViolation() after every step. Off by default: at the
  // time of writing that const query changes the following steps (see
  // docs/performance.md), so it is an opt-in cross-check.
  bool measure_violation = false;
  // Actuator schedules (nscd::bindCommandSchedules: --command texts and the scene's
  // own), applied as nscd_run applies them: at t = 0, then at the end of each step.
  std::vector<BoundSchedule> schedules;
  // If set, the time series written as `nscd_run --csv FILE --every N` writes it
  // (the first row at t = 0, then every `every` steps) ...
  std::string series_csv;
  int every = 1;
  // ... and, if set, the JSON line nscd_run prints after the run.
  std::string summary_json;
  // If set, the friction-contact problems chosen by dump_when (ProblemDump) are
  // written to this folder as nscd_run --dump-problems writes them, each file
  // name prefixed by dump_prefix.
  std::string dump_dir, dump_when = "unconverged", dump_prefix;
};

struct CaseMetrics {
  std::string status = "ok";  // ok | nonfinite | error: <message>
  long steps = 0;             // steps done
  double sim_time = 0;        // simulated in this run (from a state: t - its t)
  double wall_s = 0;
  double iters_mean = 0;
  int iters_max = 0;
  double residual_max = 0;
  long unconverged_steps = 0;
  double unconverged_residual_max = 0;  // worst residual among unconverged steps
  double max_penetration = 0;  // max over steps of StepStats::max_penetration, m
  double max_violation = 0;    // max of Simulator::constraintViolation(), m (if measured)
  double clearance_min = 0;    // smallest radial clearance of the model, m (0: none)
  double energy_initial = 0;
  double energy_final = 0;
  double energy_gain_max = 0;  // max over steps of E(t) - E(0), J
  double energy_step_gain_max = 0;  // max over steps of E(k+1) - E(k), J
  double kinetic_peak = 0;     // max over steps of the kinetic energy, J
  // Kept for the JSON summary (CaseOptions::summary_json), not in the CSV row.
  long plastic_retries = 0;
  long longer_solves = 0;  // StepStats::longer_solve
  long halved_steps = 0;  // steps taken again in halves (Settings::max_step_halvings)
  int substeps_max = 1;   // the most substeps one step took
  long frictionless_fallbacks = 0;
  long energy_capped_steps = 0;
  // The fallbacks' effect: the largest kinetic-energy gain and loss one caused against
  // the unsolved answer it replaced, relative to K(v_free) (StepStats); the same for
  // the plastic retries.
  double fallback_gain_max = 0, fallback_loss_max = 0;
  double retry_gain_max = 0, retry_loss_max = 0;
  // Step control (Settings::step_control; RunSummary): attempts rejected, steps
  // extrapolated, the shortest and longest step.
  long rejected_steps = 0, extrapolated_steps = 0;
  double h_min = 0, h_max = 0;
  StageCounts counts;        // solves per solver stage, steps per rescue (not in the CSV row)
  int problems_written = 0;  // CaseOptions::dump_dir
};

// Runs a copy of `model` for opts.duration (from opts.initial_state if set); never
// throws (errors go to status).
CaseMetrics runCase(const Model& model, const CaseOptions& opts);

// Applies one sweep parameter to a loaded model. Keys: any settings key
// (dt, tolerance, projection, ...), and the model keys
//   radial  radial clearance of every clearance joint, m
//   mu, e   friction / restitution of every clearance joint and contact pair
//   mass_scale  multiplies every body's mass and inertia
// Throws std::invalid_argument (unknown key, bad value).
void applyParam(Model& model, const std::string& key, const std::string& value);

// The model keys applyParam knows besides the settings keys.
const std::vector<std::string>& modelParamKeys();

}  // namespace nscd::sweep
