// Runs the ball and the planar clearance pendulum in nscd_sim and in Siconos,
// in one process, over a ladder of time steps and both schemes, and writes
//   OUT/runs.csv     one row per run: wall time of the stepping loop, steps, ...
//   OUT/samples.csv  the sampled trajectories (for errors and agreement)
// scripts/analysis/siconos_compare.py turns them into errors, ratios and tables.
//
// usage: nscd_siconos_compare [--out DIR] [--quick] [--scene ball|pendulum|all]
//                             [--tolerance TOL] [--min-seconds S]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "models.hpp"

using namespace nscd_siconos;

namespace {

struct Config {
  std::string out = ".";
  std::string scene = "all";
  bool quick = false;
  double tolerance = 1e-8;
  double min_seconds = 0.2;  // repeat short runs until this much time is measured
};

const char* schemeName(Scheme s) { return s == Scheme::MoreauJean ? "mj" : "cp"; }

template <class Run>
RunResult timed(Run run, const Config& c) {
  // Keep the fastest of a few repetitions: the first result carries the samples.
  RunResult best = run();
  if (!best.error.empty()) return best;
  double total = best.wall_seconds;
  for (int rep = 1; rep < 20 && total < c.min_seconds; ++rep) {
    const RunResult r = run();
    total += r.wall_seconds;
    best.wall_seconds = std::min(best.wall_seconds, r.wall_seconds);
    best.cpu_seconds = std::min(best.cpu_seconds, r.cpu_seconds);
  }
  return best;
}

void writeRun(FILE* runs, FILE* samples, const char* scene, const char* scheme, const char* engine,
              const RunOptions& o, const RunResult& r) {
  std::string apex;
  for (size_t i = 0; i < r.apex.size(); ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.9g", i ? ";" : "", r.apex[i]);
    apex += buf;
  }
  std::string err = r.error;
  std::replace(err.begin(), err.end(), ',', ';');
  std::replace(err.begin(), err.end(), '\n', ' ');
  std::fprintf(runs, "%s,%s,%s,%.9g,%.3g,%ld,%.6g,%.6g,%.6g,%.6g,%ld,%s,%s\n", scene, scheme, engine,
               o.h, o.tolerance, r.steps, r.wall_seconds,
               r.steps ? 1e6 * r.wall_seconds / r.steps : 0.0, r.cpu_seconds, r.max_penetration,
               r.unconverged_steps, apex.c_str(), err.c_str());
  std::fflush(runs);
  for (size_t i = 0; i < r.t.size(); ++i)
    std::fprintf(samples, "%s,%s,%s,%.9g,%.6f,%.12g,%.12g\n", scene, scheme, engine, o.h, r.t[i],
                 r.a[i], r.b[i]);
  std::printf("%-8s %-2s %-12s h=%-10.4g tol=%-7.1e %8.3f ms  %7.3f us/step  pen=%.2e%s%s\n",
              scene, scheme, engine, o.h, o.tolerance, 1e3 * r.wall_seconds,
              r.steps ? 1e6 * r.wall_seconds / r.steps : 0.0, r.max_penetration,
              r.error.empty() ? "" : "  ERROR: ", r.error.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  Config c;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--out") c.out = next();
    else if (a == "--scene") c.scene = next();
    else if (a == "--quick") c.quick = true;
    else if (a == "--tolerance") c.tolerance = std::atof(next());
    else if (a == "--min-seconds") c.min_seconds = std::atof(next());
    else {
      std::fprintf(stderr, "usage: %s [--out DIR] [--quick] [--scene ball|pendulum|all] "
                           "[--tolerance TOL] [--min-seconds S]\n", argv[0]);
      return 2;
    }
  }
  FILE* runs = std::fopen((c.out + "/runs.csv").c_str(), "w");
  FILE* samples = std::fopen((c.out + "/samples.csv").c_str(), "w");
  if (!runs || !samples) {
    std::fprintf(stderr, "cannot write into %s\n", c.out.c_str());
    return 1;
  }
  std::fprintf(runs, "scene,scheme,engine,h,tol,steps,wall_s,us_per_step,cpu_s,max_pen,unconverged,apex,error\n");
  std::fprintf(samples, "scene,scheme,engine,h,t,a,b\n");

  // h = 1e-3 / 2^k: every h divides the 1 ms sampling interval.
  const int levels = c.quick ? 3 : 6;
  const int ref_level = c.quick ? 6 : 9;
  const BallParams ball;
  const PendulumParams pend;
  for (Scheme scheme : {Scheme::MoreauJean, Scheme::CombinedProjection}) {
    for (int k = 0; k < levels; ++k) {
      RunOptions o;
      o.h = 1e-3 / std::ldexp(1.0, k);
      o.tolerance = c.tolerance;
      o.scheme = scheme;
      if (c.scene == "all" || c.scene == "ball") {
        writeRun(runs, samples, "ball", schemeName(scheme), "nscd", o,
                 timed([&] { return runBallNscd(ball, o); }, c));
        writeRun(runs, samples, "ball", schemeName(scheme), "siconos", o,
                 timed([&] { return runBallSiconos(ball, o); }, c));
      }
      if (c.scene == "all" || c.scene == "pendulum") {
        writeRun(runs, samples, "pendulum", schemeName(scheme), "nscd", o,
                 timed([&] { return runPendulumNscd(pend, o); }, c));
        writeRun(runs, samples, "pendulum", schemeName(scheme), "siconos", o,
                 timed([&] { return runPendulumSiconos(pend, o); }, c));
        RunOptions lin = o;
        lin.siconos_newton = false;
        writeRun(runs, samples, "pendulum", schemeName(scheme), "siconos_lin", lin,
                 timed([&] { return runPendulumSiconos(pend, lin); }, c));
      }
    }
  }
  // Converged references of the pendulum (the ball has an exact solution):
  // both engines at h = 1e-3 / 2^ref_level, tight tolerance, combined projection.
  if (c.scene == "all" || c.scene == "pendulum") {
    RunOptions o;
    o.h = 1e-3 / std::ldexp(1.0, ref_level);
    o.tolerance = 1e-12;
    o.scheme = Scheme::CombinedProjection;
    Config once = c;
    once.min_seconds = 0;
    writeRun(runs, samples, "pendulum", "cp", "nscd_ref", o,
             timed([&] { return runPendulumNscd(pend, o); }, once));
    writeRun(runs, samples, "pendulum", "cp", "siconos_ref", o,
             timed([&] { return runPendulumSiconos(pend, o); }, once));
  }
  std::fclose(runs);
  std::fclose(samples);
  return 0;
}
