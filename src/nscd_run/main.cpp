// nscd_run: the headless runner (docs/interfaces.md). Loads a scene, steps it for a
// duration with optional actuator schedules (from its initial state or from a
// state file), writes a CSV and the final state, prints one JSON line.
// Exit status: 0 done, 2 bad input, 3 the simulation failed.
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
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
#include "nscd_sim/state_file.hpp"

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

// The command line's values (docs/interfaces.md).
struct RunOptions {
  std::string scene, config, csv, dump_dir, dump_when = "unconverged";
  std::string initial_state, save_state;  // state files (docs/interfaces.md, "State files")
  std::vector<std::string> sets, commands;
  double duration = 1.0, dt = 0;
  bool dt_given = false;  // --dt on the command line, even if 0
  int every = 1;
  bool quiet = false;
};

// Bad input: the one line to print before exiting with status 2.
struct BadInput {
  std::string line;
};

void declareOptions(CLI::App& app, RunOptions& o) {
  app.add_option("scene", o.scene, "scene file (URDF with <nscd> annotations)")->required();
  app.add_option("--config", o.config, "YAML file of simulation settings");
  app.add_option("--set", o.sets, "override a setting: key=value (repeatable)");
  app.add_option("--duration", o.duration, "simulated time, s (default 1)");
  app.add_option("--dt", o.dt, "time step, s (overrides the scene)");
  app.add_option("--csv", o.csv, "write a CSV row every N steps to this file");
  app.add_option("--every", o.every, "CSV row every N steps (default 1)");
  app.add_option("--command", o.commands, "actuator schedule NAME=t0:v0,t1:v1,... (repeatable)");
  app.add_flag("--quiet", o.quiet, "no progress bar");
  app.add_option("--initial-state", o.initial_state,
                 "start from this state file (its time, poses, velocities, warm starts, commands); "
                 "--duration counts from its time");
  app.add_option("--save-state", o.save_state, "write the state at the end of the run to this file");
  app.add_option("--dump-problems", o.dump_dir,
                 "write friction-contact problems to this folder (docs/interfaces.md)");
  app.add_option("--dump-when", o.dump_when,
                 "which problems: unconverged (default), all, a step count N (every Nth step), or "
                 "stage=NAME[,NAME...] (those these solver stages finished, docs/solver.md)");
}

// --save-state's file must be writable before the run starts, not after it.
void checkSaveStatePath(const std::string& path) {
  if (path.empty()) return;
  const size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : slash == 0 ? "/" : path.substr(0, slash);
  struct stat st {};
  if (stat(path.c_str(), &st) == 0 ? (S_ISDIR(st.st_mode) || access(path.c_str(), W_OK) != 0)
                                   : access(dir.c_str(), W_OK) != 0)
    throw BadInput{"nscd_run: --save-state " + path + ": cannot write this file"};
}

// Parses and checks the command line into `o`; throws BadInput. Returns the exit
// status if the run is over already (--help).
std::optional<int> parseCommandLine(int argc, char** argv, RunOptions& o) {
  CLI::App app{"nscd_run: headless Moreau-Jean simulation of a scene (URDF + <nscd>)"};
  declareOptions(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw BadInput{std::string("nscd_run: ") + e.what() + " (see --help)"};
  }
  o.dt_given = app.count("--dt") > 0;
  if (!std::isfinite(o.duration) || o.duration < 0)
    throw BadInput{"nscd_run: --duration must be a finite number >= 0"};
  if (o.every < 1) throw BadInput{"nscd_run: --every must be >= 1"};
  checkSaveStatePath(o.save_state);
  return std::nullopt;
}

// The problem dump --dump-problems asks for (null without it); throws BadInput.
std::unique_ptr<nscd::ProblemDump> openProblemDump(const RunOptions& o) {
  std::unique_ptr<nscd::ProblemDump> dump;
  try {
    if (!o.dump_dir.empty()) dump = std::make_unique<nscd::ProblemDump>(o.dump_dir, o.dump_when);
  } catch (const std::invalid_argument& e) {
    throw BadInput{std::string("nscd_run: --dump-when ") + e.what()};
  }
  if (!o.dump_dir.empty() && access(o.dump_dir.c_str(), W_OK) != 0)
    throw BadInput{"nscd_run: --dump-problems " + o.dump_dir + ": not a writable folder"};
  return dump;
}

// The settings overrides of --config, --set and --dt, in that order (later wins).
std::vector<nscd::SettingOverride> settingOverrides(const RunOptions& o) {
  std::vector<nscd::SettingOverride> overrides;
  if (!o.config.empty()) overrides = nscd::readSettingsYaml(o.config);
  for (const std::string& s : o.sets) {
    nscd::SettingOverride ov;
    if (!nscd_run::parseSetOption(s, ov)) throw BadInput{"nscd_run: --set " + s + ": expected key=value"};
    overrides.push_back(ov);
  }
  if (o.dt != 0 || o.dt_given) {
    std::ostringstream os;
    os.precision(17);
    os << o.dt;
    overrides.push_back({"dt", os.str(), "--dt"});
  }
  return overrides;
}

// Loads the scene with its overrides and binds the --command schedules to it;
// throws BadInput.
std::unique_ptr<nscd::Simulator> loadSimulator(const RunOptions& o,
                                               std::vector<nscd::BoundSchedule>& schedules) {
  try {
    nscd::Model model = nscd::loadScene(o.scene, settingOverrides(o));
    try {
      schedules = nscd::bindCommandSchedules(o.commands, model);
    } catch (const std::invalid_argument& e) {
      throw BadInput{std::string("nscd_run: --command: ") + e.what()};
    }
    auto sim = std::make_unique<nscd::Simulator>(std::move(model));
    if (!o.initial_state.empty()) nscd::loadStateFile(o.initial_state, *sim);
    return sim;
  } catch (const nscd::StateFileError& e) {
    throw BadInput{e.what()};
  } catch (const nscd::SceneError& e) {
    throw BadInput{e.what()};
  } catch (const std::invalid_argument& e) {
    throw BadInput{std::string("nscd_run: ") + e.what()};
  } catch (const std::exception& e) {
    throw BadInput{e.what()};
  }
}

// The --csv writer (null without it); throws BadInput.
std::unique_ptr<nscd::CsvWriter> openCsv(const RunOptions& o, const nscd::Simulator& sim) {
  try {
    if (!o.csv.empty()) return std::make_unique<nscd::CsvWriter>(o.csv, sim);
  } catch (const std::exception& e) {
    throw BadInput{std::string("nscd_run: ") + e.what()};
  }
  return nullptr;
}

// The per-step figures of a run, gathered for its RunSummary.
struct RunTally {
  long iters_sum = 0;
  int iters_max = 0, unconverged = 0, plastic_retries = 0, frictionless_fallbacks = 0, energy_capped = 0;
  int longer_solves = 0;
  int halved = 0, substeps_max = 1;
  long rejected = 0, extrapolated = 0;
  double residual_max = 0, max_pen = 0, h_min = INFINITY, h_max = 0;
  nscd::StageCounts counts;

  void add(const nscd::StepStats& s, nscd::StepStatus st) {
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
  }

  // Copies the tallied fields into `summary`.
  void fill(nscd::RunSummary& summary) const {
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
    summary.rejected_steps = rejected;
    summary.extrapolated_steps = extrapolated;
    summary.h_min = h_max > 0 ? h_min : 0;
    summary.h_max = h_max;
    summary.counts = counts;
  }
};

// What is needed to step a loaded scene through its run.
struct RunParts {
  nscd::Simulator& sim;
  const std::vector<nscd::BoundSchedule>& schedules;
  nscd::CsvWriter* writer;  // null: no CSV
  ProgressBar& progress;
  const nscd::RunClock& clock;
};

// Steps to the end of the run: round(duration / dt) fixed steps, or adaptive ones
// until the sim time reaches t0 + duration (nscd::RunClock). `k` is the step being
// taken (the problem dump names its files by it). Returns the exit status: 0, or
// 3 if the state went non-finite (then reported on stderr).
int stepToEnd(const RunParts& run, const RunOptions& o, long& k, RunTally& tally,
              const std::function<double()>& wall) {
  nscd::Simulator& sim = run.sim;
  for (k = 1; !run.clock.finished(sim, k - 1); ++k) {
    run.clock.prepare(sim, run.schedules, k);  // the command at the end of the step
    const nscd::StepStatus st = sim.step();
    const nscd::StepStats& s = sim.stats();
    tally.add(s, st);
    if (st == nscd::StepStatus::NonFinite) {
      run.progress.finish(sim.state().t - run.clock.start(), wall());
      std::cerr << "nscd_run: simulation failed at t=" << sim.state().t
                << " s: non-finite state (last solver residual " << s.residual << " after "
                << s.iterations << " iterations)" << std::endl;
      return 3;
    }
    if (run.writer && k % o.every == 0) run.writer->writeRow(sim);
    if ((k & 255) == 0) run.progress.update(sim.state().t - run.clock.start(), wall());
  }
  return 0;
}

// Runs the loaded scene, writes its CSV and prints the JSON summary; returns the
// exit status (stepToEnd).
int runAndReport(const RunOptions& o, nscd::Simulator& sim,
                 const std::vector<nscd::BoundSchedule>& schedules, nscd::CsvWriter* writer,
                 nscd::ProblemDump* dump) {
  const double h = sim.model().settings.dt;
  long k = 0;
  if (dump) sim.setProblemObserver([&](const nscd::ProblemView& v) { dump->write(v, k); });
  const bool adaptive = sim.model().settings.step_control == nscd::StepControl::Adaptive;
  const long steps = static_cast<long>(std::llround(o.duration / h));
  const nscd::RunClock clock(sim, o.duration);
  // From a state file the commands are the state's (those of the run that wrote it).
  if (o.initial_state.empty()) nscd::applySchedules(schedules, 0.0, sim);
  if (writer) writer->writeRow(sim);
  const double energy_initial = sim.energy().total();
  ProgressBar progress(!o.quiet && isatty(2), adaptive ? o.duration : steps * h);
  RunTally tally;
  const auto t0 = std::chrono::steady_clock::now();
  const std::function<double()> wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const int status = stepToEnd({sim, schedules, writer, progress, clock}, o, k, tally, wall);
  const double wall_s = wall();
  progress.finish(sim.state().t - clock.start(), wall_s);
  if (dump) std::cerr << "nscd_run: " << dump->written() << " problems written to " << o.dump_dir << std::endl;
  if (dump) sim.setProblemObserver(nullptr);  // it refers to k, which ends here
  nscd::RunSummary summary;
  summary.steps = status == 0 ? k - 1 : k;
  summary.sim_time = sim.state().t - clock.start();  // simulated in this run
  summary.wall_s = wall_s;
  summary.energy_initial = energy_initial;
  summary.energy_final = sim.energy().total();
  tally.fill(summary);
  std::cout << nscd::runSummaryJson(summary) << std::endl;
  if (status == 0 && !o.save_state.empty()) {
    try {
      std::ostringstream note;
      note.precision(17);
      note << "written by nscd_run " << o.scene << " (dt " << sim.model().settings.dt << ", "
           << (sim.model().settings.step_control == nscd::StepControl::Adaptive ? "adaptive" : "fixed")
           << " steps) at t = " << sim.state().t << " s";
      nscd::writeStateFile(o.save_state, sim, note.str());
    } catch (const nscd::StateFileError& e) {
      std::cerr << "nscd_run: --save-state " << e.what() << std::endl;
      return 2;
    }
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    RunOptions opts;
    if (const std::optional<int> exit_status = parseCommandLine(argc, argv, opts)) return *exit_status;
    std::unique_ptr<nscd::ProblemDump> dump = openProblemDump(opts);
    std::vector<nscd::BoundSchedule> schedules;
    std::unique_ptr<nscd::Simulator> sim = loadSimulator(opts, schedules);
    std::unique_ptr<nscd::CsvWriter> writer = openCsv(opts, *sim);
    return runAndReport(opts, *sim, schedules, writer.get(), dump.get());
  } catch (const BadInput& e) {
    return badInput(e.line);
  }
}
