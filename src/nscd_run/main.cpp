// nscd_run: the headless runner (docs/interfaces.md). Loads a scene, steps it for a
// duration with optional actuator schedules, writes a CSV, prints one JSON line.
// Exit status: 0 done, 2 bad input, 3 the simulation failed.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "csv_writer.hpp"
#include "problem_dump.hpp"
#include "run_summary.hpp"
#include "set_option.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"

namespace {

int badInput(const std::string& line) {
  std::cerr << line << std::endl;
  return 2;
}

class ProgressBar {
 public:
  ProgressBar(bool enabled, double duration) : enabled_(enabled), duration_(duration) {}
  void update(double t, double wall) {
    if (!enabled_ || wall - last_ < 0.25) return;
    last_ = wall;
    draw(t, wall);
  }
  void finish(double t, double wall) {
    if (!enabled_ || last_ < 0) return;  // never drawn: a short run stays silent
    draw(t, wall);
    std::fputc('\n', stderr);
  }

 private:
  void draw(double t, double wall) {
    const double frac = duration_ > 0 ? std::min(1.0, t / duration_) : 1.0;
    const int width = 30, done = static_cast<int>(frac * width);
    std::string bar(done, '#');
    bar.resize(width, ' ');
    const double eta = frac > 0 ? wall * (1 - frac) / frac : 0;
    std::fprintf(stderr, "\r[%s] %5.1f%%  t=%.6g/%.6g s  rtf %.3g  eta %.0f s ", bar.c_str(),
                 100 * frac, t, duration_, wall > 0 ? t / wall : 0.0, eta);
    std::fflush(stderr);
  }
  bool enabled_;
  double duration_;
  double last_ = -1;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nscd_run: headless Moreau-Jean simulation of a scene (URDF + <nscd>)"};
  std::string scene, config, csv, dump_dir, dump_when = "unconverged";
  std::vector<std::string> sets, commands;
  double duration = 1.0, dt = 0;
  int every = 1;
  bool quiet = false;
  app.add_option("scene", scene, "scene file (URDF with <nscd> annotations)")->required();
  app.add_option("--config", config, "YAML file of simulation settings");
  app.add_option("--set", sets, "override a setting: key=value (repeatable)");
  app.add_option("--duration", duration, "simulated time, s (default 1)");
  app.add_option("--dt", dt, "time step, s (overrides the scene)");
  app.add_option("--csv", csv, "write a CSV row every N steps to this file");
  app.add_option("--every", every, "CSV row every N steps (default 1)");
  app.add_option("--command", commands, "actuator schedule NAME=t0:v0,t1:v1,... (repeatable)");
  app.add_flag("--quiet", quiet, "no progress bar");
  app.add_option("--dump-problems", dump_dir,
                 "write friction-contact problems to this folder (docs/interfaces.md)");
  app.add_option("--dump-when", dump_when,
                 "which problems: unconverged (default), all, a step count N (every Nth step), or "
                 "stage=NAME[,NAME...] (those these solver stages finished, docs/solver.md)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return badInput(std::string("nscd_run: ") + e.what() + " (see --help)");
  }
  if (!std::isfinite(duration) || duration < 0)
    return badInput("nscd_run: --duration must be a finite number >= 0");
  if (every < 1) return badInput("nscd_run: --every must be >= 1");
  std::unique_ptr<nscd::ProblemDump> dump;
  try {
    if (!dump_dir.empty()) dump = std::make_unique<nscd::ProblemDump>(dump_dir, dump_when);
  } catch (const std::invalid_argument& e) {
    return badInput(std::string("nscd_run: --dump-when ") + e.what());
  }
  if (!dump_dir.empty() && access(dump_dir.c_str(), W_OK) != 0)
    return badInput("nscd_run: --dump-problems " + dump_dir + ": not a writable folder");

  std::vector<nscd::SettingOverride> overrides;
  std::unique_ptr<nscd::Simulator> sim;
  std::vector<nscd::BoundSchedule> schedules;
  try {
    if (!config.empty()) overrides = nscd::readSettingsYaml(config);
    for (const std::string& s : sets) {
      nscd::SettingOverride o;
      if (!nscd_run::parseSetOption(s, o))
        return badInput("nscd_run: --set " + s + ": expected key=value");
      overrides.push_back(o);
    }
    if (dt != 0 || app.count("--dt")) {
      std::ostringstream os;
      os.precision(17);
      os << dt;
      overrides.push_back({"dt", os.str(), "--dt"});
    }
    nscd::Model model = nscd::loadScene(scene, overrides);
    try {
      schedules = nscd::bindCommandSchedules(commands, model);
    } catch (const std::invalid_argument& e) {
      return badInput(std::string("nscd_run: --command: ") + e.what());
    }
    sim = std::make_unique<nscd::Simulator>(std::move(model));
  } catch (const nscd::SceneError& e) {
    return badInput(e.what());
  } catch (const std::invalid_argument& e) {
    return badInput(std::string("nscd_run: ") + e.what());
  } catch (const std::exception& e) {
    return badInput(e.what());
  }

  std::unique_ptr<nscd::CsvWriter> writer;
  try {
    if (!csv.empty()) writer = std::make_unique<nscd::CsvWriter>(csv, *sim);
  } catch (const std::exception& e) {
    return badInput(std::string("nscd_run: ") + e.what());
  }

  const double h = sim->model().settings.dt;
  long k = 0;
  if (dump) sim->setProblemObserver([&](const nscd::ProblemView& v) { dump->write(v, k); });
  // Fixed steps: round(duration / dt) of them; adaptive: until the sim time
  // reaches duration (scheduled_step.hpp).
  const bool adaptive = sim->model().settings.step_control == nscd::StepControl::Adaptive;
  const long steps = static_cast<long>(std::llround(duration / h));
  nscd::applySchedules(schedules, 0.0, *sim);
  if (writer) writer->writeRow(*sim);
  const double energy_initial = sim->energy().total();
  ProgressBar progress(!quiet && isatty(2), adaptive ? duration : steps * h);
  long iters_sum = 0;
  int iters_max = 0, unconverged = 0, plastic_retries = 0, frictionless_fallbacks = 0, energy_capped = 0;
  int longer_solves = 0;
  int halved = 0, substeps_max = 1;
  long rejected = 0, extrapolated = 0;
  double residual_max = 0, max_pen = 0, h_min = INFINITY, h_max = 0;
  nscd::StageCounts counts;
  const auto t0 = std::chrono::steady_clock::now();
  auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  int status = 0;
  for (k = 1; !nscd::runFinished(*sim, k - 1, duration); ++k) {
    nscd::prepareScheduledStep(*sim, schedules, k, duration);  // the command at the end of the step
    const nscd::StepStatus st = sim->step();
    const nscd::StepStats& s = sim->stats();
    rejected += s.rejected;
    extrapolated += s.extrapolated;
    h_min = std::min(h_min, s.h);
    h_max = std::max(h_max, s.h);
    iters_sum += s.iterations;
    iters_max = std::max(iters_max, s.iterations);
    if (std::isfinite(s.residual)) residual_max = std::max(residual_max, s.residual);
    max_pen = std::max(max_pen, s.max_penetration);
    if (st == nscd::StepStatus::NotConverged) ++unconverged;
    plastic_retries += s.plastic_retry;
    longer_solves += s.longer_solve;
    halved += s.substeps > 1;
    substeps_max = std::max(substeps_max, s.substeps);
    frictionless_fallbacks += s.frictionless_fallback;
    energy_capped += s.energy_capped;
    counts.addStep(s);
    if (st == nscd::StepStatus::NonFinite) {
      progress.finish(sim->state().t, wall());
      std::cerr << "nscd_run: simulation failed at t=" << sim->state().t
                << " s: non-finite state (last solver residual " << s.residual << " after "
                << s.iterations << " iterations)" << std::endl;
      status = 3;
      break;
    }
    if (writer && k % every == 0) writer->writeRow(*sim);
    if ((k & 255) == 0) progress.update(sim->state().t, wall());
  }
  const double wall_s = wall();
  progress.finish(sim->state().t, wall_s);
  if (dump) std::cerr << "nscd_run: " << dump->written() << " problems written to " << dump_dir << std::endl;
  nscd::RunSummary summary;
  summary.steps = status == 0 ? k - 1 : k;
  summary.sim_time = sim->state().t;
  summary.wall_s = wall_s;
  summary.iters_sum = iters_sum;
  summary.iters_max = iters_max;
  summary.residual_max = residual_max;
  summary.unconverged_steps = unconverged;
  summary.plastic_retries = plastic_retries;
  summary.longer_solves = longer_solves;
  summary.halved_steps = halved;
  summary.substeps_max = substeps_max;
  summary.frictionless_fallbacks = frictionless_fallbacks;
  summary.energy_capped_steps = energy_capped;
  summary.max_penetration = max_pen;
  summary.energy_initial = energy_initial;
  summary.energy_final = sim->energy().total();
  summary.rejected_steps = rejected;
  summary.extrapolated_steps = extrapolated;
  summary.h_min = h_max > 0 ? h_min : 0;
  summary.h_max = h_max;
  summary.counts = counts;
  std::cout << nscd::runSummaryJson(summary) << std::endl;
  return status;
}
