// nscd_sweep: a parameter sweep of one scene over all local cores, one shard of
// it for a scheduler (--shard i/n), and the merge of shard CSVs (--merge).
// Exit status: 0 done (even if some runs failed: see the status column), 2 bad input.
#include <unistd.h>

#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "csv_row.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "parallel_for.hpp"
#include "run_case.hpp"
#include "sweep_grid.hpp"

namespace {

int badInput(const std::string& line) {
  std::cerr << "nscd_sweep: " << line << std::endl;
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace nscd::sweep;
  CLI::App app{
      "nscd_sweep: run a scene over the Cartesian product of parameter values.\n"
      "Parameters: any setting (dt, tolerance, projection, planar, ...) and\n"
      "radial, mu, e (every clearance joint / contact pair), mass_scale."};
  std::string scene, csv, shard = "0/1";
  std::vector<std::string> params, sets, merge;
  double duration = 0.1;
  int jobs = defaultJobs();
  bool list = false, no_timing = false, quiet = false, violation = false;
  app.add_option("scene", scene, "scene file (URDF with <nscd> annotations)");
  app.add_option("--param", params, "sweep axis: key=v1,v2,... | key=log:lo:hi:n | key=lin:lo:hi:n");
  app.add_option("--set", sets, "fixed setting key=value for every run (repeatable)");
  app.add_option("--duration", duration, "simulated time per run, s (default 0.1)");
  app.add_option("--jobs", jobs, "worker threads (default: all cores)");
  app.add_option("--shard", shard, "run only shard i of n: runs k with k mod n == i (default 0/1)");
  app.add_option("--csv", csv, "output file (default: standard output)");
  app.add_option("--merge", merge, "merge shard CSVs into one (sorted by run) on standard output");
  app.add_flag("--list", list, "print the runs of this shard and their parameters, run nothing");
  app.add_flag("--no-timing", no_timing, "leave out wall_s (output identical across reruns)");
  app.add_flag("--violation", violation, "also call Simulator::constraintViolation() every step");
  app.add_flag("--quiet", quiet, "no progress on standard error");
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
  if (scene.empty()) return badInput("a scene file is required (or --merge)");
  if (!(duration > 0)) return badInput("--duration must be > 0");
  if (jobs < 1) return badInput("--jobs must be >= 1");

  std::vector<SweepAxis> axes;
  int shard_i = 0, shard_n = 1;
  nscd::Model base;
  try {
    for (const std::string& p : params) axes.push_back(parseAxis(p));
    parseShard(shard, shard_i, shard_n);
    std::vector<nscd::SettingOverride> ov;
    for (const std::string& s : sets) {
      const size_t eq = s.find('=');
      if (eq == std::string::npos || eq == 0) return badInput("--set " + s + ": expected key=value");
      ov.push_back({s.substr(0, eq), s.substr(eq + 1), "--set"});
    }
    base = nscd::loadScene(scene, ov);
    // Check every axis value once against the model, before spending any time.
    for (const SweepAxis& a : axes)
      for (const std::string& v : a.values) {
        nscd::Model m = base;
        applyParam(m, a.key, v);
      }
  } catch (const std::exception& e) {
    return badInput(e.what());
  }

  const long total = gridSize(axes);
  std::vector<long> mine;
  for (long k = shard_i; k < total; k += shard_n) mine.push_back(k);

  std::unique_ptr<std::ofstream> file;
  if (!csv.empty()) {
    file = std::make_unique<std::ofstream>(csv);
    if (!*file) return badInput("cannot write " + csv);
  }
  std::ostream& out = file ? *file : std::cout;
  std::string header = "run,runs";
  for (const SweepAxis& a : axes) header += "," + a.key;
  if (list) {
    out << header << "\n";
    for (long k : mine) {
      const std::vector<int> idx = gridPoint(axes, k);
      out << k << "," << total;
      for (size_t i = 0; i < axes.size(); ++i) out << "," << axes[i].values[idx[i]];
      out << "\n";
    }
    return 0;
  }

  std::vector<std::string> rows(mine.size());
  std::mutex mtx;
  long done = 0;
  parallelFor(static_cast<long>(mine.size()), jobs, [&](long j) {
    const long k = mine[j];
    const std::vector<int> idx = gridPoint(axes, k);
    std::string row = std::to_string(k) + "," + std::to_string(total);
    for (size_t i = 0; i < axes.size(); ++i) row += "," + axes[i].values[idx[i]];
    nscd::Model m = base;
    CaseMetrics r;
    try {
      for (size_t i = 0; i < axes.size(); ++i) applyParam(m, axes[i].key, axes[i].values[idx[i]]);
      CaseOptions opt;
      opt.duration = duration;
      opt.measure_violation = violation;
      r = runCase(m, opt);
    } catch (const std::exception& e) {
      r.status = std::string("error: ") + e.what();
    }
    rows[j] = row + "," + metricsRow(r, !no_timing);
    if (!quiet && isatty(2)) {
      std::lock_guard<std::mutex> lock(mtx);
      ++done;
      std::cerr << "\rnscd_sweep: shard " << shard_i << "/" << shard_n << ": " << done << "/"
                << mine.size() << " runs" << std::flush;
    }
  });
  if (!quiet && isatty(2) && !mine.empty()) std::cerr << "\n";
  out << header << "," << metricsHeader(!no_timing) << "\n";
  for (const std::string& r : rows) out << r << "\n";
  out.flush();
  if (!out) return badInput("write failed");
  return 0;
}
