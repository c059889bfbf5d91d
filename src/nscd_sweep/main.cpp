// nscd_sweep: a parameter sweep of one scene (or of several: --scenes) over all
// local cores, one shard of it for a scheduler (--shard i/n), and the merge of
// shard CSVs (--merge). Runs may apply actuator schedules (--command) and write
// their time series as nscd_run --csv does (--series DIR), and start from a state
// file (--initial-state).
// Exit status: 0 done (even if some runs failed: see the status column), 2 bad input.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <mutex>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "csv_row.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/state_file.hpp"
#include "parallel_for.hpp"
#include "run_case.hpp"
#include "sweep_grid.hpp"

namespace {

int badInput(const std::string& line) {
  std::cerr << "nscd_sweep: " << line << std::endl;
  return 2;
}

std::string wallText(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}

// The command line's values (see --help).
struct SweepOptions {
  std::string scene, csv, shard = "0/1", series, initial_state;
  std::vector<std::string> scenes, params, sets, merge, commands;
  double duration = 0.1;
  int jobs = nscd::sweep::defaultJobs(), every = 1;
  bool list = false, no_timing = false, quiet = false, violation = false, progress = false;
  bool scene_axis = false;   // --scenes given: the scene is a sweep axis
  bool every_given = false;  // --every on the command line
};

// Bad input: the line (after "nscd_sweep: ") to print before exiting with status 2.
struct BadInput {
  std::string line;
};

void declareOptions(CLI::App& app, SweepOptions& o) {
  app.add_option("scene", o.scene, "scene file (URDF with <nscd> annotations)");
  app.add_option("--scenes", o.scenes,
                 "sweep over these scene files instead (the slowest axis; CSV column 'scene')");
  app.add_option("--param", o.params, "sweep axis: key=v1,v2,... | key=log:lo:hi:n | key=lin:lo:hi:n");
  app.add_option("--set", o.sets, "fixed setting key=value for every run (repeatable)");
  app.add_option("--command", o.commands,
                 "actuator schedule NAME=t0:v0,t1:v1,... for every run, as nscd_run's (repeatable)");
  app.add_option("--duration", o.duration, "simulated time per run, s (default 0.1)");
  app.add_option("--jobs", o.jobs, "worker threads (default: all cores)");
  app.add_option("--shard", o.shard, "run only shard i of n: runs k with k mod n == i (default 0/1)");
  app.add_option("--csv", o.csv, "output file (default: standard output)");
  app.add_option("--series", o.series,
                 "also write run k's time series to DIR/run_<k>.csv (as nscd_run --csv) and "
                 "nscd_run's JSON line to DIR/run_<k>.json");
  app.add_option("--every", o.every, "with --series: a series row every N steps (default 1)");
  app.add_option("--initial-state", o.initial_state,
                 "start every run from this state file (as nscd_run --initial-state: --duration "
                 "counts from its time); refused if it does not fit a scene");
  app.add_option("--merge", o.merge, "merge shard CSVs into one (sorted by run) on standard output");
  app.add_flag("--list", o.list, "print the runs of this shard and their parameters, run nothing");
  app.add_flag("--no-timing", o.no_timing, "leave out wall_s (output identical across reruns)");
  app.add_flag("--violation", o.violation, "also call Simulator::constraintViolation() every step");
  app.add_flag("--quiet", o.quiet, "no progress on standard error");
  app.add_flag("--progress", o.progress, "one line per finished run on standard error, even when not a terminal");
}

// Parses the command line into `o`; throws BadInput. Returns the exit status if
// the run is over already (--help).
std::optional<int> parseCommandLine(int argc, char** argv, SweepOptions& o) {
  CLI::App app{
      "nscd_sweep: run a scene (or each of --scenes) over the Cartesian product of\n"
      "parameter values. Parameters: any setting (dt, tolerance, projection, planar,\n"
      "...) and radial, mu, e (every clearance joint / contact pair), mass_scale."};
  declareOptions(app, o);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw BadInput{std::string(e.what()) + " (see --help)"};
  }
  o.scene_axis = app.count("--scenes") > 0;
  o.every_given = app.count("--every") > 0;
  return std::nullopt;
}

// --merge: writes the merged shard CSVs to standard output; returns the exit status.
int mergeShards(const SweepOptions& o) {
  try {
    const long n = nscd::sweep::mergeCsv(o.merge, std::cout, std::cerr);
    if (!o.quiet) std::cerr << "nscd_sweep: merged " << n << " rows from " << o.merge.size() << " files\n";
    return 0;
  } catch (const std::exception& e) {
    return badInput(e.what());
  }
}

// Checks the options of a sweep (not --merge) and makes `o.scenes` its scene list;
// throws BadInput.
void checkSweepOptions(SweepOptions& o) {
  if (o.scene_axis && !o.scene.empty()) throw BadInput{"give one scene file or --scenes, not both"};
  if (o.scene_axis && o.scenes.empty()) throw BadInput{"--scenes needs at least one scene file"};
  if (!o.scene_axis) {
    if (o.scene.empty()) throw BadInput{"a scene file is required (or --scenes, or --merge)"};
    o.scenes = {o.scene};
  }
  if (!(o.duration > 0)) throw BadInput{"--duration must be > 0"};
  if (o.jobs < 1) throw BadInput{"--jobs must be >= 1"};
  if (o.every < 1) throw BadInput{"--every must be >= 1"};
  if (o.every_given && o.series.empty()) throw BadInput{"--every needs --series DIR"};
}

// A state holds the poses of the scene's clearances (each pin in its hole): with
// another clearance a run would start with pins inside the bearing wall or loose.
// The other parameters (settings, friction, restitution, masses) leave the model's
// bodies, joints and contacts as they are, which is all a state depends on
// (include/nscd_sim/state_file.hpp); throws BadInput.
void checkAxesFitAState(const SweepOptions& o, const std::vector<nscd::sweep::SweepAxis>& axes) {
  if (o.initial_state.empty()) return;
  for (const nscd::sweep::SweepAxis& a : axes)
    if (a.key == "radial")
      throw BadInput{"--param radial: a state file fits only the clearances it was written with; "
                     "sweep radial without --initial-state, or write a state per clearance"};
}

// The sweep, checked: its axes, this shard, and every scene loaded with the
// schedules bound to it. The runs only read it (each copies its model).
struct Sweep {
  std::vector<nscd::sweep::SweepAxis> axes;
  int shard_i = 0, shard_n = 1;
  std::vector<nscd::Model> bases;  // one per scene
  std::vector<std::vector<nscd::BoundSchedule>> schedules;  // one list per scene
  std::vector<nscd::State> states;  // --initial-state, read for each scene (else empty)
  long points = 0;  // grid points per scene
  long total = 0;   // runs over all scenes and shards
};

// The --set texts as settings overrides; throws BadInput.
std::vector<nscd::SettingOverride> fixedSettings(const SweepOptions& o) {
  std::vector<nscd::SettingOverride> ov;
  for (const std::string& s : o.sets) {
    const size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0) throw BadInput{"--set " + s + ": expected key=value"};
    ov.push_back({s.substr(0, eq), s.substr(eq + 1), "--set"});
  }
  return ov;
}

// Loads `file` into the sweep, binds the schedules to it and tries every axis
// value on it; throws BadInput.
void addScene(const SweepOptions& o, const std::string& file,
              const std::vector<nscd::SettingOverride>& ov, Sweep& sw) {
  try {
    sw.bases.push_back(nscd::loadScene(file, ov));
  } catch (const std::exception& e) {
    const std::string what = e.what();
    // The loader's messages start with FILE:LINE; name the file if one does not.
    throw BadInput{what.rfind(file, 0) == 0 ? what : file + ": " + what};
  }
  try {
    sw.schedules.push_back(nscd::bindCommandSchedules(o.commands, sw.bases.back()));
  } catch (const std::invalid_argument& e) {
    throw BadInput{"--command: " + file + ": " + e.what()};
  }
  if (!o.initial_state.empty()) {
    // Checked against the scene (fingerprint, sizes, values) once, here; the runs
    // share the state. No parameter changes what the check compares
    // (checkAxesFitAState).
    try {
      sw.states.push_back(nscd::readStateFile(o.initial_state, nscd::Simulator(sw.bases.back())));
    } catch (const nscd::StateFileError& e) {
      throw BadInput{o.scene_axis ? std::string(e.what()) + " (scene " + file + ")" : std::string(e.what())};
    }
  }
  for (const nscd::sweep::SweepAxis& a : sw.axes)
    for (const std::string& v : a.values) {
      nscd::Model m = sw.bases.back();
      try {
        nscd::sweep::applyParam(m, a.key, v);
      } catch (const std::exception& e) {
        throw BadInput{o.scene_axis ? file + ": " + e.what() : std::string(e.what())};
      }
    }
}

// Every scene loaded, and every axis value and schedule checked against it,
// before spending any time; throws BadInput.
Sweep loadSweep(const SweepOptions& o) {
  Sweep sw;
  try {
    for (const std::string& p : o.params) sw.axes.push_back(nscd::sweep::parseAxis(p));
    checkAxesFitAState(o, sw.axes);
    nscd::sweep::parseShard(o.shard, sw.shard_i, sw.shard_n);
    const std::vector<nscd::SettingOverride> ov = fixedSettings(o);
    for (const std::string& file : o.scenes) addScene(o, file, ov, sw);
  } catch (const std::exception& e) {
    throw BadInput{e.what()};
  }
  sw.points = nscd::sweep::gridSize(sw.axes);
  sw.total = sw.points * static_cast<long>(o.scenes.size());
  return sw;
}

// The CSV header's leading columns: run, runs, scene (with --scenes), the axes.
std::string leadingHeader(const SweepOptions& o, const Sweep& sw) {
  std::string header = o.scene_axis ? "run,runs,scene" : "run,runs";
  for (const nscd::sweep::SweepAxis& a : sw.axes) header += "," + a.key;
  return header;
}

// Run k's leading cells: scene k / points, grid point k mod points (the scene
// varies slowest).
std::string leadingCells(const SweepOptions& o, const Sweep& sw, long k) {
  std::string row = std::to_string(k) + "," + std::to_string(sw.total);
  if (o.scene_axis) row += "," + nscd::sweep::cell(o.scenes[k / sw.points]);
  const std::vector<int> idx = nscd::sweep::gridPoint(sw.axes, k % sw.points);
  for (size_t i = 0; i < sw.axes.size(); ++i) row += "," + sw.axes[i].values[idx[i]];
  return row;
}

// Runs sweep run k (never throws: an error goes to the status).
nscd::sweep::CaseMetrics runOne(const SweepOptions& o, const Sweep& sw, long k) {
  using namespace nscd::sweep;
  const long s = k / sw.points;
  const std::vector<int> idx = gridPoint(sw.axes, k % sw.points);
  nscd::Model m = sw.bases[s];
  CaseMetrics r;
  try {
    for (size_t i = 0; i < sw.axes.size(); ++i) applyParam(m, sw.axes[i].key, sw.axes[i].values[idx[i]]);
    CaseOptions opt;
    opt.duration = o.duration;
    opt.measure_violation = o.violation;
    opt.schedules = sw.schedules[s];
    if (!sw.states.empty()) opt.initial_state = &sw.states[s];
    if (!o.series.empty()) {
      const std::string stem = (std::filesystem::path(o.series) / ("run_" + std::to_string(k))).string();
      opt.series_csv = stem + ".csv";
      opt.summary_json = stem + ".json";
      opt.every = o.every;
    }
    r = runCase(m, opt);
  } catch (const std::exception& e) {
    r.status = std::string("error: ") + e.what();
  }
  return r;
}

// Runs this shard's runs (`mine`) over the worker threads; returns their CSV
// rows in order. Each run writes only its own slot of the rows and its own
// series files; the progress count and stderr are behind the mutex.
std::vector<std::string> runShard(const SweepOptions& o, const Sweep& sw, const std::vector<long>& mine) {
  std::vector<std::string> rows(mine.size());
  std::mutex mtx;
  long done = 0;
  const bool tty_progress = !o.quiet && !o.progress && isatty(2);
  nscd::sweep::parallelFor(static_cast<long>(mine.size()), o.jobs, [&](long j) {
    const long k = mine[j];
    const nscd::sweep::CaseMetrics r = runOne(o, sw, k);
    rows[j] = leadingCells(o, sw, k) + "," + nscd::sweep::metricsRow(r, !o.no_timing);
    if (o.progress || tty_progress) {
      std::lock_guard<std::mutex> lock(mtx);
      ++done;
      if (o.progress)
        std::cerr << "nscd_sweep: shard " << sw.shard_i << "/" << sw.shard_n << ": " << done << "/"
                  << mine.size() << " runs: run " << k
                  << (o.scene_axis ? " (" + o.scenes[k / sw.points] + ")" : "") << " " << r.status
                  << " in " << wallText(r.wall_s) << " s" << std::endl;
      else
        std::cerr << "\rnscd_sweep: shard " << sw.shard_i << "/" << sw.shard_n << ": " << done << "/"
                  << mine.size() << " runs" << std::flush;
    }
  });
  if (tty_progress && !mine.empty()) std::cerr << "\n";
  return rows;
}

// Makes the --series folder; throws BadInput if it cannot be written.
void makeSeriesFolder(const std::string& series) {
  std::error_code ec;
  std::filesystem::create_directories(series, ec);
  if (ec || access(series.c_str(), W_OK) != 0) throw BadInput{"--series " + series + ": not a writable folder"};
}

// Loads and checks the sweep, then lists or runs this shard's runs; returns the
// exit status, throws BadInput.
int sweep(SweepOptions& o) {
  checkSweepOptions(o);
  const Sweep sw = loadSweep(o);
  std::vector<long> mine;
  for (long k = sw.shard_i; k < sw.total; k += sw.shard_n) mine.push_back(k);
  if (!o.series.empty() && !o.list) makeSeriesFolder(o.series);
  std::unique_ptr<std::ofstream> file;
  if (!o.csv.empty()) {
    file = std::make_unique<std::ofstream>(o.csv);
    if (!*file) throw BadInput{"cannot write " + o.csv};
  }
  std::ostream& out = file ? *file : std::cout;
  const std::string header = leadingHeader(o, sw);
  if (o.list) {
    out << header << "\n";
    for (long k : mine) out << leadingCells(o, sw, k) << "\n";
    return 0;
  }
  const std::vector<std::string> rows = runShard(o, sw, mine);
  out << header << "," << nscd::sweep::metricsHeader(!o.no_timing) << "\n";
  for (const std::string& r : rows) out << r << "\n";
  out.flush();
  if (!out) throw BadInput{"write failed"};
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    SweepOptions opts;
    if (const std::optional<int> exit_status = parseCommandLine(argc, argv, opts)) return *exit_status;
    if (!opts.merge.empty()) return mergeShards(opts);
    return sweep(opts);
  } catch (const BadInput& e) {
    return badInput(e.line);
  }
}
