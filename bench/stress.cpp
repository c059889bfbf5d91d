// nscd_stress: the stress suite and the long soak.
//
//   nscd_stress [--runs N] [--seed S] [--steps K] [--jobs J] [--csv FILE]
//               [--dump-problems DIR [--dump-when W]]
//     N randomised clearance pendulums (stress_cases.hpp), K steps each (default 1000); one CSV
//     row per run (no wall times: reruns compare byte for byte); a summary on stdout with the
//     solves each solver stage finished and the steps each rescue took (docs/solver.md).
//     --dump-problems: the problems W chooses (as nscd_run's --dump-when), caseK_stepN_....txt.
//   nscd_stress --case K [--seed S] --write FILE.urdf
//     writes case K's scene and prints the nscd_run command that replays it.
//   nscd_stress --soak STEPS [--soak-scene FILE] [--sample-every N] [--soak-csv FILE]
//     one long run, resident memory (/proc/self/statm) and heap allocations
//     (a counting operator new) sampled along the way.
// Exit status: 0 all checks passed, 1 a check failed, 2 bad input.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "../src/nscd_sweep/csv_row.hpp"
#include "../src/nscd_sweep/parallel_for.hpp"
#include "../src/nscd_sweep/run_case.hpp"
#include "../src/nscd_sweep/stress_cases.hpp"
#include "problem_dump.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/simulator.hpp"

// ---------------------------------------------------------------- allocation count
// (GCC 12 mistakes the malloc/free pairing below for a mismatch once inlined.)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<long> g_allocations{0};
}
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {

using namespace nscd::sweep;

// Acceptance thresholds (docs/performance.md states them).
constexpr double kPenetrationRel = 0.01;  // max penetration / radial clearance, with projection
// Energy gain: E(t) - E(0) must stay below this fraction of the scene's energy
// scale (sum m g l plus the peak kinetic energy): round-off of E is ~1e-16 of
// that scale; 1e-9 leaves room for the solver tolerance on the impulses.
constexpr double kEnergyGainRel = 1e-9;

struct Row {
  StressCase c;
  CaseMetrics m;
  double pen_rel = 0, viol_rel = 0, gain_rel = 0;
};

std::string caseColumns() { return "case,links,planar,radial,mu,e,dt,mass_ratio,m1,m2"; }
std::string caseCells(const StressCase& c) {
  return std::to_string(c.index) + "," + std::to_string(c.links) + "," + (c.planar ? "1" : "0") + "," +
         fmt(c.radial) + "," + fmt(c.mu) + "," + fmt(c.e) + "," + fmt(c.dt) + "," + fmt(c.mass_ratio) +
         "," + fmt(c.m1) + "," + fmt(c.m2);
}

long residentKiB() {
  std::ifstream f("/proc/self/statm");
  long size = 0, resident = 0;
  f >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

int soak(long steps, const std::string& scene, long every, const std::string& csv) {
  nscd::Model model;
  try {
    model = nscd::loadScene(scene);
  } catch (const std::exception& e) {
    std::cerr << e.what() << std::endl;
    return 2;
  }
  nscd::Simulator sim(std::move(model));
  std::unique_ptr<std::ofstream> out;
  if (!csv.empty()) {
    out = std::make_unique<std::ofstream>(csv);
    *out << "step,t,rss_kib,allocations\n";
  }
  const long warmup = std::min(steps, std::max(1000L, steps / 10));  // buffers reach their size
  long rss_start = 0, rss_min = 0, rss_max = 0, allocs = 0, nonfinite = 0, unconverged = 0;
  double max_pen = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 1; k <= steps; ++k) {
    const long a0 = g_allocations.load(std::memory_order_relaxed);
    const nscd::StepStatus st = sim.step();
    // Heap allocations inside step() only (the sampling below allocates too).
    if (k > warmup) allocs += g_allocations.load(std::memory_order_relaxed) - a0;
    if (st == nscd::StepStatus::NonFinite) {
      ++nonfinite;
      break;
    }
    unconverged += st == nscd::StepStatus::NotConverged;
    max_pen = std::max(max_pen, sim.stats().max_penetration);
    if (k == warmup) rss_start = rss_min = rss_max = residentKiB();
    if (k % every == 0 || k == steps) {
      const long rss = residentKiB();
      if (k >= warmup) {
        rss_min = std::min(rss_min, rss);
        rss_max = std::max(rss_max, rss);
      }
      if (out) *out << k << "," << fmt(sim.state().t) << "," << rss << "," << g_allocations.load() << "\n";
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const long rss_end = residentKiB();
  std::printf(
      "{\"soak_steps\":%ld,\"scene\":\"%s\",\"dt\":%.6g,\"wall_s\":%.3f,\"us_per_step\":%.3f,"
      "\"rss_kib_after_warmup\":%ld,\"rss_kib_end\":%ld,\"rss_kib_min\":%ld,\"rss_kib_max\":%ld,"
      "\"allocations_after_warmup\":%ld,\"allocations_per_step\":%.4g,\"nonfinite\":%ld,"
      "\"unconverged_steps\":%ld,\"max_penetration\":%.6g}\n",
      steps, scene.c_str(), sim.model().settings.dt, wall, 1e6 * wall / steps, rss_start, rss_end,
      rss_min, rss_max, allocs, double(allocs) / std::max(1L, steps - warmup), nonfinite, unconverged,
      max_pen);
  return nonfinite == 0 && rss_max - rss_start <= 64 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nscd_stress: randomised clearance-joint stress suite and long soak"};
  long runs = 1000, steps = 1000, first = 0, soak_steps = 0, sample_every = 10000, case_k = -1;
  unsigned long long seed = 1;
  int jobs = defaultJobs();
  std::string csv, write, soak_scene, soak_csv, dump_dir, dump_when = "unconverged";
  bool quiet = false, violation = false;
  app.add_option("--runs", runs, "number of randomised runs (default 1000)");
  app.add_option("--first", first, "index of the first case (default 0)");
  app.add_option("--seed", seed, "random seed (default 1)");
  app.add_option("--steps", steps, "steps per run (default 1000)");
  app.add_option("--jobs", jobs, "worker threads (default: all cores)");
  app.add_option("--csv", csv, "write one row per run to this file");
  app.add_option("--case", case_k, "with --write: the case to write");
  app.add_option("--write", write, "write case --case's scene to this URDF file");
  app.add_option("--soak", soak_steps, "soak: run this many steps of one scene");
  app.add_option("--soak-scene", soak_scene, "soak scene (default urdf/clearance_pendulum.urdf)");
  app.add_option("--sample-every", sample_every, "soak: memory sample every N steps (default 10000)");
  app.add_option("--soak-csv", soak_csv, "soak: write the memory samples to this CSV");
  app.add_flag("--violation", violation, "also call Simulator::constraintViolation() every step");
  app.add_flag("--quiet", quiet, "no progress on standard error");
  app.add_option("--dump-problems", dump_dir, "write friction-contact problems to this folder");
  app.add_option("--dump-when", dump_when,
                 "which: unconverged (default), all, N (every Nth step) or stage=NAME[,NAME...]");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "nscd_stress: " << e.what() << " (see --help)" << std::endl;
    return 2;
  }
  if (runs < 0 || steps < 1 || jobs < 1 || sample_every < 1) {
    std::cerr << "nscd_stress: --runs >= 0, --steps >= 1, --jobs >= 1, --sample-every >= 1" << std::endl;
    return 2;
  }
  try {
    nscd::ProblemDump check(dump_dir, dump_when);
  } catch (const std::invalid_argument& e) {
    std::cerr << "nscd_stress: --dump-when " << e.what() << std::endl;
    return 2;
  }
  if (soak_steps > 0) {
#ifdef NSCD_SOURCE_DIR
    if (soak_scene.empty()) soak_scene = std::string(NSCD_SOURCE_DIR) + "/urdf/clearance_pendulum.urdf";
#endif
    return soak(soak_steps, soak_scene, sample_every, soak_csv);
  }
  if (!write.empty()) {
    if (case_k < 0) {
      std::cerr << "nscd_stress: --write needs --case K" << std::endl;
      return 2;
    }
    const StressCase c = makeStressCase(seed, case_k);
    std::ofstream(write) << c.urdf;
    std::printf("nscd_run %s --duration %.17g --quiet\n", write.c_str(), steps * c.dt);
    return 0;
  }

  std::vector<Row> rows(runs);
  std::atomic<long> done{0};
  const auto t0 = std::chrono::steady_clock::now();
  parallelFor(runs, jobs, [&](long i) {
    Row& r = rows[i];
    r.c = makeStressCase(seed, first + i);
    try {
      nscd::Model m = nscd::loadSceneFromString(r.c.urdf, "stress_" + std::to_string(r.c.index));
      CaseOptions opt;
      opt.duration = steps * r.c.dt;
      opt.measure_violation = violation;
      opt.dump_dir = dump_dir;
      opt.dump_when = dump_when;
      opt.dump_prefix = "case" + std::to_string(r.c.index) + "_";
      r.m = runCase(m, opt);
    } catch (const std::exception& e) {
      r.m.status = std::string("error: ") + e.what();
    }
    r.pen_rel = r.m.max_penetration / r.c.radial;
    r.viol_rel = r.m.max_violation / r.c.radial;
    r.gain_rel = r.m.energy_gain_max / (r.c.energy_scale + r.m.kinetic_peak);
    const long d = ++done;
    if (!quiet && isatty(2) && (d % 10 == 0 || d == runs))
      std::fprintf(stderr, "\rnscd_stress: %ld/%ld runs", d, runs);
  });
  if (!quiet && isatty(2) && runs > 0) std::fputc('\n', stderr);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  if (!csv.empty()) {
    std::ofstream f(csv);
    f << caseColumns() << "," << metricsHeader(false) << ",pen_rel,violation_rel,energy_gain_rel\n";
    for (const Row& r : rows)
      f << caseCells(r.c) << "," << metricsRow(r.m, false) << "," << fmt(r.pen_rel) << ","
        << fmt(r.viol_rel) << "," << fmt(r.gain_rel) << "\n";
  }

  long failed = 0, pen_bad = 0, gain_bad = 0, unconv_runs = 0, unconv_steps = 0, total_steps = 0;
  long frictionless = 0, capped = 0;  // steps that took a fallback (counted unconverged too)
  double fb_gain = 0, fb_loss = 0;      // their largest relative kinetic-energy change
  long retries = 0;                     // steps taken plastic after Newton's law was unsolved
  double rt_gain = 0, rt_loss = 0;      // and their largest relative kinetic-energy change
  long halved = 0;                      // steps taken again in halves (max_step_halvings)
  long longer = 0;                      // steps whose last solve took 10 times the budget
  int substeps_max = 1;                 // the most substeps one step took
  double pen_max = 0, viol_max = 0, gain_max = -1e300, unconv_res = 0;
  nscd::StageCounts counts;  // solves per solver stage, steps per rescue
  long dumped = 0;
  long worst_pen = -1, worst_gain = -1, first_failed = -1;
  for (const Row& r : rows) {
    total_steps += r.m.steps;
    counts.add(r.m.counts);
    dumped += r.m.problems_written;
    if (r.m.status != "ok") {
      ++failed;
      if (first_failed < 0) first_failed = r.c.index;
      continue;
    }
    if (r.pen_rel > pen_max) pen_max = r.pen_rel, worst_pen = r.c.index;
    viol_max = std::max(viol_max, r.viol_rel);
    if (r.gain_rel > gain_max) gain_max = r.gain_rel, worst_gain = r.c.index;
    pen_bad += r.pen_rel > kPenetrationRel;
    gain_bad += r.gain_rel > kEnergyGainRel;
    unconv_runs += r.m.unconverged_steps > 0;
    unconv_steps += r.m.unconverged_steps;
    unconv_res = std::max(unconv_res, r.m.unconverged_residual_max);
    retries += r.m.plastic_retries;
    longer += r.m.longer_solves;
    halved += r.m.halved_steps;
    substeps_max = std::max(substeps_max, r.m.substeps_max);
    rt_gain = std::max(rt_gain, r.m.retry_gain_max);
    rt_loss = std::max(rt_loss, r.m.retry_loss_max);
    frictionless += r.m.frictionless_fallbacks;
    capped += r.m.energy_capped_steps;
    fb_gain = std::max(fb_gain, r.m.fallback_gain_max);
    fb_loss = std::max(fb_loss, r.m.fallback_loss_max);
  }
  std::printf(
      "{\"runs\":%ld,\"seed\":%llu,\"steps_per_run\":%ld,\"total_steps\":%ld,\"wall_s\":%.3f,"
      "\"failed\":%ld,\"first_failed_case\":%ld,\"pen_rel_max\":%.4g,\"worst_pen_case\":%ld,"
      "\"pen_rel_over_1pct\":%ld,\"violation_rel_max\":%.4g,\"energy_gain_rel_max\":%.4g,"
      "\"worst_gain_case\":%ld,\"energy_gain_over_tol\":%ld,\"energy_tol_rel\":%.1g,"
      "\"unconverged_runs\":%ld,\"unconverged_steps\":%ld,\"unconverged_residual_max\":%.4g,"
      "\"halved_steps\":%ld,\"substeps_max\":%d,\"longer_solve_steps\":%ld,"
      "\"plastic_retry_steps\":%ld,\"retry_kinetic_gain_max\":%.3g,\"retry_kinetic_loss_max\":%.3g,"
      "\"frictionless_fallback_steps\":%ld,\"fallback_kinetic_gain_max\":%.3g,"
      "\"fallback_kinetic_loss_max\":%.3g,\"energy_capped_steps\":%ld,%s}\n",
      runs, seed, steps, total_steps, wall, failed, first_failed, pen_max, worst_pen, pen_bad,
      viol_max, gain_max, worst_gain, gain_bad, kEnergyGainRel, unconv_runs, unconv_steps, unconv_res,
      halved, substeps_max, longer, retries, rt_gain, rt_loss, frictionless, fb_gain, fb_loss, capped,
      counts.jsonFields().c_str());
  if (!dump_dir.empty()) std::cerr << "nscd_stress: " << dumped << " problems written to " << dump_dir << std::endl;
  return failed == 0 && pen_bad == 0 && gain_bad == 0 ? 0 : 1;
}
