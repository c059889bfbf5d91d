// One headless run with failure watch and figures (see run_case.hpp).
#include "run_case.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <memory>
#include <stdexcept>

#include "csv_writer.hpp"
#include "problem_dump.hpp"
#include "run_summary.hpp"

#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"

namespace nscd::sweep {

namespace {

// The smallest radial clearance of the model (0: none).
double smallestClearance(const Model& model) {
  double c = 0;
  for (const ClearanceJoint& cj : model.clearance_joints) c = c == 0 ? cj.radial : std::min(c, cj.radial);
  return c;
}

// A case's running figures that CaseMetrics does not keep.
struct CaseTally {
  long iters_sum = 0;
  double h_min = INFINITY;
  double e_prev = 0;  // the energy after the previous step
};

// Adds a step's solver and rescue figures to `r`.
void addStepStats(const StepStats& s, CaseMetrics& r, CaseTally& t) {
  r.rejected_steps += s.rejected;
  r.extrapolated_steps += s.extrapolated;
  t.h_min = std::min(t.h_min, s.h);
  r.h_max = std::max(r.h_max, s.h);
  r.h_min = t.h_min;
  t.iters_sum += s.iterations;
  r.iters_max = std::max(r.iters_max, s.iterations);
  if (std::isfinite(s.residual)) r.residual_max = std::max(r.residual_max, s.residual);
  r.plastic_retries += s.plastic_retry;
  r.longer_solves += s.longer_solve;
  r.halved_steps += s.substeps > 1;
  r.substeps_max = std::max(r.substeps_max, s.substeps);
  if (s.plastic_retry && std::isfinite(s.plastic_retry_kinetic_change)) {
    r.retry_gain_max = std::max(r.retry_gain_max, s.plastic_retry_kinetic_change);
    r.retry_loss_max = std::max(r.retry_loss_max, -s.plastic_retry_kinetic_change);
  }
  r.frictionless_fallbacks += s.frictionless_fallback;
  if (s.frictionless_fallback && std::isfinite(s.fallback_kinetic_change)) {
    r.fallback_gain_max = std::max(r.fallback_gain_max, s.fallback_kinetic_change);
    r.fallback_loss_max = std::max(r.fallback_loss_max, -s.fallback_kinetic_change);
  }
  r.energy_capped_steps += s.energy_capped;
  r.counts.addStep(s);
}

// Adds the outcome of a step with a finite state to `r`: convergence, penetration,
// violation (if measured), energy. False if the energy is not finite.
bool addStepOutcome(const Simulator& sim, StepStatus st, const CaseOptions& opts, CaseMetrics& r,
                    CaseTally& t) {
  const StepStats& s = sim.stats();
  if (st == StepStatus::NotConverged) {
    ++r.unconverged_steps;
    r.unconverged_residual_max = std::max(r.unconverged_residual_max, s.residual);
  }
  r.max_penetration = std::max(r.max_penetration, s.max_penetration);
  if (opts.measure_violation) r.max_violation = std::max(r.max_violation, sim.constraintViolation());
  const EnergyReport en = sim.energy();
  const double e = en.total();
  if (!std::isfinite(e)) return false;
  r.energy_gain_max = std::max(r.energy_gain_max, e - r.energy_initial);
  r.energy_step_gain_max = std::max(r.energy_step_gain_max, e - t.e_prev);
  r.kinetic_peak = std::max(r.kinetic_peak, en.kinetic);
  t.e_prev = e;
  return true;
}

// Steps `sim` through the run `clock` times as nscd_run does, tallying into `r` and
// writing the series rows; stops at a non-finite state or energy (status
// "nonfinite"). `k` is the step being taken (the problem dump names its files by it).
void stepCase(Simulator& sim, const CaseOptions& opts, const RunClock& clock, CsvWriter* writer, long& k,
              CaseMetrics& r, CaseTally& t) {
  const int every = std::max(1, opts.every);
  for (k = 1; !clock.finished(sim, k - 1); ++k) {
    clock.prepare(sim, opts.schedules, k);  // the command at the end of the step
    const StepStatus st = sim.step();
    r.steps = k;
    addStepStats(sim.stats(), r, t);
    if (st == StepStatus::NonFinite || !addStepOutcome(sim, st, opts, r, t)) {
      r.status = "nonfinite";
      break;
    }
    if (writer && k % every == 0) writer->writeRow(sim);
  }
}

// Writes the JSON line nscd_run prints for this run to `path`; throws if it cannot.
void writeSummaryJson(const CaseMetrics& r, long iters_sum, const std::string& path) {
  RunSummary js;
  js.steps = r.steps;
  js.sim_time = r.sim_time;
  js.wall_s = r.wall_s;
  js.iters_sum = iters_sum;
  js.iters_max = r.iters_max;
  js.residual_max = r.residual_max;
  js.unconverged_steps = r.unconverged_steps;
  js.plastic_retries = r.plastic_retries;
  js.longer_solves = r.longer_solves;
  js.halved_steps = r.halved_steps;
  js.substeps_max = r.substeps_max;
  js.frictionless_fallbacks = r.frictionless_fallbacks;
  js.energy_capped_steps = r.energy_capped_steps;
  js.max_penetration = r.max_penetration;
  js.energy_initial = r.energy_initial;
  js.energy_final = r.energy_final;
  js.rejected_steps = r.rejected_steps;
  js.extrapolated_steps = r.extrapolated_steps;
  js.h_min = r.h_min;
  js.h_max = r.h_max;
  js.counts = r.counts;
  std::ofstream f(path);
  f << runSummaryJson(js) << "\n";
  if (!f) throw std::runtime_error(path + ": cannot write");
}

}  // namespace

CaseMetrics runCase(const Model& model, const CaseOptions& opts) {
  CaseMetrics r;
  r.clearance_min = smallestClearance(model);
  const auto t0 = std::chrono::steady_clock::now();
  try {
    Simulator sim(model);
    // From a state the commands are the state's (those of the run that wrote it).
    if (opts.initial_state)
      sim.setState(*opts.initial_state);
    else
      applySchedules(opts.schedules, 0.0, sim);
    const RunClock clock(sim, opts.duration);
    std::unique_ptr<CsvWriter> writer;
    if (!opts.series_csv.empty()) {
      writer = std::make_unique<CsvWriter>(opts.series_csv, sim);
      writer->writeRow(sim);
    }
    r.energy_initial = sim.energy().total();
    CaseTally tally;
    tally.e_prev = r.energy_initial;
    long k = 0;
    std::unique_ptr<ProblemDump> dump;
    if (!opts.dump_dir.empty()) {
      dump = std::make_unique<ProblemDump>(opts.dump_dir, opts.dump_when, opts.dump_prefix);
      sim.setProblemObserver([&](const ProblemView& v) { dump->write(v, k); });
    }
    stepCase(sim, opts, clock, writer.get(), k, r, tally);
    if (dump) r.problems_written = dump->written();
    r.sim_time = sim.state().t - clock.start();
    r.energy_final = sim.energy().total();
    r.iters_mean = r.steps > 0 ? static_cast<double>(tally.iters_sum) / r.steps : 0.0;
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (!opts.summary_json.empty()) writeSummaryJson(r, tally.iters_sum, opts.summary_json);
  } catch (const std::exception& ex) {
    r.status = std::string("error: ") + ex.what();
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

namespace {

double number(const std::string& key, const std::string& v) {
  size_t used = 0;
  double x = 0;
  try {
    x = std::stod(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || !std::isfinite(x))
    throw std::invalid_argument("parameter '" + key + "': '" + v + "' is not a finite number");
  return x;
}

}  // namespace

const std::vector<std::string>& modelParamKeys() {
  static const std::vector<std::string> keys = {"radial", "mu", "e", "mass_scale"};
  return keys;
}

void applyParam(Model& model, const std::string& key, const std::string& value) {
  if (key == "radial") {
    const double c = number(key, value);
    if (c <= 0) throw std::invalid_argument("parameter 'radial' must be > 0");
    if (model.clearance_joints.empty())
      throw std::invalid_argument("parameter 'radial': the scene has no clearance joint");
    // Bumps sit at 1.5 (r + c) unless the scene placed them: keep them clear of the pin.
    for (ClearanceJoint& cj : model.clearance_joints) {
      const double old_default = 1.5 * (cj.radius + cj.radial);
      if (std::abs(cj.bump_at - old_default) <= 1e-12 * old_default) cj.bump_at = 1.5 * (cj.radius + c);
      cj.radial = c;
    }
  } else if (key == "mu" || key == "e") {
    const double x = number(key, value);
    if (x < 0 || (key == "e" && x > 1))
      throw std::invalid_argument("parameter '" + key + "' out of range");
    for (ClearanceJoint& cj : model.clearance_joints) (key == "mu" ? cj.mu : cj.e) = x;
    for (ContactPair& cp : model.contacts) (key == "mu" ? cp.mu : cp.e) = x;
  } else if (key == "mass_scale") {
    const double s = number(key, value);
    if (s <= 0) throw std::invalid_argument("parameter 'mass_scale' must be > 0");
    for (Body& b : model.bodies) {
      b.mass *= s;
      b.inertia *= s;
    }
  } else {
    try {
      applySetting(model.settings, SettingOverride{key, value, "--param"});
    } catch (const SceneError& e) {
      throw std::invalid_argument(e.what());
    }
  }
}

}  // namespace nscd::sweep
