// nscd_sweep: a parameter sweep of one scene (or of several: --scenes) over all
// local cores, one shard of it for a scheduler (--shard i/n), and the merge of
// shard CSVs (--merge). Runs may apply actuator schedules (--command) and write
// their time series as nscd_run --csv does (--series DIR).
// Exit status: 0 done (even if some runs failed: see the status column), 2 bad input.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "csv_row.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
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

}  // namespace

int main(int argc, char** argv) {
  using namespace nscd::sweep;
  CLI::App app{
      "nscd_sweep: run a scene (or each of --scenes) over the Cartesian product of\n"
      "parameter values. Parameters: any setting (dt, tolerance, projection, planar,\n"
      "...) and radial, mu, e (every clearance joint / contact pair), mass_scale."};
  std::string scene, csv, shard = "0/1", series;
  std::vector<std::string> scenes, params, sets, merge, commands;
  double duration = 0.1;
  int jobs = defaultJobs(), every = 1;
  bool list = false, no_timing = false, quiet = false, violation = false, progress = false;
  app.add_option("scene", scene, "scene file (URDF with <nscd> annotations)");
  app.add_option("--scenes", scenes,
                 "sweep over these scene files instead (the slowest axis; CSV column 'scene')");
  app.add_option("--param", params, "sweep axis: key=v1,v2,... | key=log:lo:hi:n | key=lin:lo:hi:n");
  app.add_option("--set", sets, "fixed setting key=value for every run (repeatable)");
  app.add_option("--command", commands,
                 "actuator schedule NAME=t0:v0,t1:v1,... for every run, as nscd_run's (repeatable)");
  app.add_option("--duration", duration, "simulated time per run, s (default 0.1)");
  app.add_option("--jobs", jobs, "worker threads (default: all cores)");
  app.add_option("--shard", shard, "run only shard i of n: runs k with k mod n == i (default 0/1)");
  app.add_option("--csv", csv, "output file (default: standard output)");
  app.add_option("--series", series,
                 "also write run k's time series to DIR/run_<k>.csv (as nscd_run --csv) and "
                 "nscd_run's JSON line to DIR/run_<k>.json");
  app.add_option("--every", every, "with --series: a series row every N steps (default 1)");
  app.add_option("--merge", merge, "merge shard CSVs into one (sorted by run) on standard output");
  app.add_flag("--list", list, "print the runs of this shard and their parameters, run nothing");
  app.add_flag("--no-timing", no_timing, "leave out wall_s (output identical across reruns)");
  app.add_flag("--violation", violation, "also call Simulator::constraintViolation() every step");
  app.add_flag("--quiet", quiet, "no progress on standard error");
  app.add_flag("--progress", progress, "one line per finished run on standard error, even when not a terminal");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return badInput(std::string(e.what()) + " (see --help)");
  }

  if (!merge.empty()) {
    try {
      const long n = mergeCsv(merge, std::cout, std::cerr);
      if (!quiet) std::cerr << "nscd_sweep: merged " << n << " rows from " << merge.size() << " files\n";
      return 0;
    } catch (const std::exception& e) {
      return badInput(e.what());
    }
  }
  const bool scene_axis = app.count("--scenes") > 0;
  if (scene_axis && !scene.empty()) return badInput("give one scene file or --scenes, not both");
  if (scene_axis && scenes.empty()) return badInput("--scenes needs at least one scene file");
  if (!scene_axis) {
    if (scene.empty()) return badInput("a scene file is required (or --scenes, or --merge)");
    scenes = {scene};
  }
  if (!(duration > 0)) return badInput("--duration must be > 0");
  if (jobs < 1) return badInput("--jobs must be >= 1");
  if (every < 1) return badInput("--every must be >= 1");
  if (app.count("--every") && series.empty()) return badInput("--every needs --series DIR");

  std::vector<SweepAxis> axes;
  int shard_i = 0, shard_n = 1;
  // Every scene loaded, and every axis value and schedule checked against it,
  // before spending any time; the runs then only read these (one copy each).
  std::vector<nscd::Model> bases;
  std::vector<std::vector<nscd::BoundSchedule>> schedules;
  try {
    for (const std::string& p : params) axes.push_back(parseAxis(p));
    parseShard(shard, shard_i, shard_n);
    std::vector<nscd::SettingOverride> ov;
    for (const std::string& s : sets) {
      const size_t eq = s.find('=');
      if (eq == std::string::npos || eq == 0) return badInput("--set " + s + ": expected key=value");
      ov.push_back({s.substr(0, eq), s.substr(eq + 1), "--set"});
    }
    for (const std::string& file : scenes) {
      try {
        bases.push_back(nscd::loadScene(file, ov));
      } catch (const std::exception& e) {
        const std::string what = e.what();
        // The loader's messages start with FILE:LINE; name the file if one does not.
        return badInput(what.rfind(file, 0) == 0 ? what : file + ": " + what);
      }
      try {
        schedules.push_back(nscd::bindCommandSchedules(commands, bases.back()));
      } catch (const std::invalid_argument& e) {
        return badInput("--command: " + file + ": " + e.what());
      }
      for (const SweepAxis& a : axes)
        for (const std::string& v : a.values) {
          nscd::Model m = bases.back();
          try {
            applyParam(m, a.key, v);
          } catch (const std::exception& e) {
            return badInput(scene_axis ? file + ": " + e.what() : std::string(e.what()));
          }
        }
    }
  } catch (const std::exception& e) {
    return badInput(e.what());
  }

  const long points = gridSize(axes);
  const long total = points * static_cast<long>(scenes.size());
  std::vector<long> mine;
  for (long k = shard_i; k < total; k += shard_n) mine.push_back(k);

  if (!series.empty() && !list) {
    std::error_code ec;
    std::filesystem::create_directories(series, ec);
    if (ec || access(series.c_str(), W_OK) != 0)
      return badInput("--series " + series + ": not a writable folder");
  }
  std::unique_ptr<std::ofstream> file;
  if (!csv.empty()) {
    file = std::make_unique<std::ofstream>(csv);
    if (!*file) return badInput("cannot write " + csv);
  }
  std::ostream& out = file ? *file : std::cout;
  std::string header = scene_axis ? "run,runs,scene" : "run,runs";
  for (const SweepAxis& a : axes) header += "," + a.key;
  // Run k: scene k / points, grid point k mod points (the scene varies slowest).
  auto leading = [&](long k) {
    std::string row = std::to_string(k) + "," + std::to_string(total);
    if (scene_axis) row += "," + cell(scenes[k / points]);
    const std::vector<int> idx = gridPoint(axes, k % points);
    for (size_t i = 0; i < axes.size(); ++i) row += "," + axes[i].values[idx[i]];
    return row;
  };
  if (list) {
    out << header << "\n";
    for (long k : mine) out << leading(k) << "\n";
    return 0;
  }

  // Each run writes only its own slot of `rows` and its own series files; the
  // models and schedules are shared read-only; the progress count and stderr
  // are behind the mutex.
  std::vector<std::string> rows(mine.size());
  std::mutex mtx;
  long done = 0;
  const bool tty_progress = !quiet && !progress && isatty(2);
  parallelFor(static_cast<long>(mine.size()), jobs, [&](long j) {
    const long k = mine[j];
    const long s = k / points;
    const std::vector<int> idx = gridPoint(axes, k % points);
    nscd::Model m = bases[s];
    CaseMetrics r;
    try {
      for (size_t i = 0; i < axes.size(); ++i) applyParam(m, axes[i].key, axes[i].values[idx[i]]);
      CaseOptions opt;
      opt.duration = duration;
      opt.measure_violation = violation;
      opt.schedules = schedules[s];
      if (!series.empty()) {
        const std::string stem = (std::filesystem::path(series) / ("run_" + std::to_string(k))).string();
        opt.series_csv = stem + ".csv";
        opt.summary_json = stem + ".json";
        opt.every = every;
      }
      r = runCase(m, opt);
    } catch (const std::exception& e) {
      r.status = std::string("error: ") + e.what();
    }
    rows[j] = leading(k) + "," + metricsRow(r, !no_timing);
    if (progress || tty_progress) {
      std::lock_guard<std::mutex> lock(mtx);
      ++done;
      if (progress)
        std::cerr << "nscd_sweep: shard " << shard_i << "/" << shard_n << ": " << done << "/"
                  << mine.size() << " runs: run " << k << (scene_axis ? " (" + scenes[s] + ")" : "")
                  << " " << r.status << " in " << wallText(r.wall_s) << " s" << std::endl;
      else
        std::cerr << "\rnscd_sweep: shard " << shard_i << "/" << shard_n << ": " << done << "/"
                  << mine.size() << " runs" << std::flush;
    }
  });
  if (tty_progress && !mine.empty()) std::cerr << "\n";
  out << header << "," << metricsHeader(!no_timing) << "\n";
  for (const std::string& r : rows) out << r << "\n";
  out.flush();
  if (!out) return badInput("write failed");
  return 0;
}
