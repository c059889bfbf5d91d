// nscd_work_precision: error versus work.
//
// Each scene runs over time steps h and solver tolerances; each run is compared
// with a converged reference (h_ref much smaller, tightest tolerance) on a common
// time grid (every sample_dt): position error of every body's centre of mass
// (max and RMS over bodies and samples), and the scene's key force (clearance
// joint + contact normal forces), averaged over each sample interval so that runs
// with different h compare impulse for impulse (relative RMS error).
// Writes one CSV row per run and prints the observed order of convergence (least
// squares slope of log error against log h, at the tightest tolerance).
// --adaptive-tols adds runs with the adaptive step control (Settings::step_control;
// rtol = atol = each value, dt = --adaptive-dt the largest step, the solver at
// --adaptive-solver-tol), their steps cut at the sample times (the CSV's h column
// is then the largest step, its step_control column "adaptive"). --ref-adaptive TOL
// makes the reference such a run at rtol = atol = TOL (for smooth scenes, where a
// fixed-step reference of a first-order scheme is less accurate than the runs).
// pos_err_end: the position error at the last sample alone.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "../src/nscd_sweep/parallel_for.hpp"
#include "../test/physics_scenes.hpp"
#include "nscd_sim/command_schedule.hpp"
#include "nscd_sim/scene_loader.hpp"
#include "nscd_sim/scheduled_step.hpp"
#include "nscd_sim/simulator.hpp"

namespace {

struct Scene {
  std::string name;
  std::string text;   // URDF text (built-in scenes) ...
  std::string path;   // ... or a scene file
  double duration = 0.2;
  double sample_dt = 1e-3;
  std::vector<std::string> commands;  // --command texts NAME=t0:v0,... (checked when read)
};

struct Trace {
  std::vector<double> pos;    // sample-major: [sample][body][xyz]
  std::vector<double> force;  // key force averaged over each sample interval
  std::string status = "ok";
  long steps = 0;
  double wall_s = 0, iters_mean = 0;
  long unconverged = 0;
  long rejected = 0;  // adaptive runs
};

struct Job {
  int scene = 0;
  double h = 0, tol = 0;
  bool reference = false;
  double adaptive_tol = 0;  // > 0: adaptive step control, rtol = atol = this, h the largest step
  Trace trace;
};

std::string fmt(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", x);
  return b;
}

std::string fmt6(double x) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

nscd::Model load(const Scene& s, double h, double tol, double adaptive_tol = 0) {
  std::vector<nscd::SettingOverride> ov = {{"dt", fmt(h), "work_precision"},
                                           {"tolerance", fmt(tol), "work_precision"}};
  if (adaptive_tol > 0)
    for (const char* key : {"rtol", "atol"}) ov.push_back({key, fmt(adaptive_tol), "work_precision"});
  if (adaptive_tol > 0) ov.push_back({"step_control", "adaptive", "work_precision"});
  return s.path.empty() ? nscd::loadSceneFromString(s.text, s.name, ov) : nscd::loadScene(s.path, ov);
}

double keyForce(const nscd::Simulator& sim) {
  double f = 0;
  for (size_t j = 0; j < sim.model().clearance_joints.size(); ++j) f += sim.clearanceNormalForce(int(j));
  for (size_t p = 0; p < sim.model().contacts.size(); ++p) f += sim.contactNormalForce(int(p));
  return f;
}

Trace runTrace(const Scene& s, double h, double tol, double adaptive_tol) {
  Trace tr;
  try {
    nscd::Simulator sim(load(s, h, tol, adaptive_tol));
    const bool adaptive = adaptive_tol > 0;
    const long stride = std::llround(s.sample_dt / h);
    const long samples = std::llround(s.duration / s.sample_dt);
    if (!adaptive && (stride < 1 || std::abs(stride * h - s.sample_dt) > 1e-9 * s.sample_dt))
      throw std::runtime_error("h does not divide the sample interval");
    // The --command schedules of the scene's actuators (one list serves every scene
    // file), and the scene's own schedules for the others, as nscd_run binds them: the
    // C-60's seating moment is one.
    std::vector<std::string> texts;
    for (const std::string& c : s.commands)
      if (sim.model().findActuator(nscd::parseCommandSchedule(c).actuator) >= 0) texts.push_back(c);
    const std::vector<nscd::BoundSchedule> schedules = nscd::bindCommandSchedules(texts, sim.model());
    const int nb = static_cast<int>(sim.model().bodies.size());
    tr.pos.reserve(static_cast<size_t>(std::max(0L, samples) + 1) * nb * 3);  // no allocation while timed
    tr.force.reserve(static_cast<size_t>(std::max(0L, samples)));
    auto record = [&] {
      for (int b = 0; b < nb; ++b)
        for (int i = 0; i < 3; ++i) tr.pos.push_back(sim.state().bodies[b].x[i]);
    };
    nscd::applySchedules(schedules, 0.0, sim);
    record();
    long iters = 0, k = 0;
    const auto t0 = std::chrono::steady_clock::now();
    for (long j = 1; j <= samples; ++j) {
      double impulse = 0;
      const double sample_end = j * s.sample_dt;
      // Fixed: `stride` steps, the commands at k h (as nscd_run); adaptive: steps
      // until the sample time, the last one ending there.
      for (long i = 1; adaptive ? sim.state().t < sample_end : i <= stride; ++i) {
        ++k;
        nscd::prepareScheduledStep(sim, schedules, k, sample_end);
        const nscd::StepStatus st = sim.step();
        ++tr.steps;
        iters += sim.stats().iterations;
        tr.rejected += sim.stats().rejected;
        if (st == nscd::StepStatus::NonFinite) throw std::runtime_error("non-finite state");
        tr.unconverged += st == nscd::StepStatus::NotConverged;
        impulse += keyForce(sim) * sim.stats().h;
      }
      tr.force.push_back(impulse / s.sample_dt);
      record();
    }
    tr.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    tr.iters_mean = tr.steps ? double(iters) / tr.steps : 0;
  } catch (const std::exception& e) {
    tr.status = std::string("error: ") + e.what();
    for (char& c : tr.status)
      if (c == ',') c = ';';
  }
  return tr;
}

struct Errors {
  double pos_max = NAN, pos_rms = NAN, force_rel = NAN, pos_end = NAN;
};

Errors compare(const Trace& t, const Trace& ref) {
  Errors e;
  if (t.status != "ok" || ref.status != "ok" || t.pos.size() != ref.pos.size()) return e;
  double mx = 0, ss = 0;
  for (size_t i = 0; i < t.pos.size(); i += 3) {
    const double dx = t.pos[i] - ref.pos[i], dy = t.pos[i + 1] - ref.pos[i + 1], dz = t.pos[i + 2] - ref.pos[i + 2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    mx = std::max(mx, std::sqrt(d2));
    ss += d2;
  }
  e.pos_max = mx;
  e.pos_rms = std::sqrt(ss / (t.pos.size() / 3));
  // The last sample: its bodies' triples are the last nb of pos (nb = pos per sample / 3).
  const size_t per_sample = t.pos.size() / (t.force.size() + 1);
  double end = 0;
  for (size_t i = t.pos.size() - per_sample; i < t.pos.size(); i += 3) {
    const double dx = t.pos[i] - ref.pos[i], dy = t.pos[i + 1] - ref.pos[i + 1], dz = t.pos[i + 2] - ref.pos[i + 2];
    end = std::max(end, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  e.pos_end = end;
  double df = 0, fr = 0;
  for (size_t j = 0; j < t.force.size(); ++j) {
    df += (t.force[j] - ref.force[j]) * (t.force[j] - ref.force[j]);
    fr += ref.force[j] * ref.force[j];
  }
  e.force_rel = fr > 0 ? std::sqrt(df / fr) : NAN;
  return e;
}

// Least-squares slope of log(err) against log(h) over the finite, positive errors.
double order(const std::vector<double>& h, const std::vector<double>& err) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < h.size(); ++i) {
    if (!(err[i] > 0) || !std::isfinite(err[i])) continue;
    const double x = std::log(h[i]), y = std::log(err[i]);
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  if (n < 2) return NAN;
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

std::vector<double> parseList(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
  return v;
}

std::vector<Scene> builtinScenes(std::string_view source_dir) {
  using namespace nscd_test;
  std::vector<Scene> s;
  // Clearance pendulum (50 um, mu 0.1, e 0), released at 0.5 rad: 3D and planar.
  s.push_back({"pendulum_3d", clearancePendulumScene(50e-6, 0.1, 2e-3, 0.1, 0.5, 1e-4, true, "false"), "", 0.2, 1e-3, {}});
  s.push_back({"pendulum_planar", clearancePendulumScene(50e-6, 0.1, 2e-3, 0.1, 0.5, 1e-4, true, "xy"), "", 0.2, 1e-3, {}});
  // Journal at rest: the sleeve drops by its clearance onto the pin and rests.
  s.push_back({"sleeve", sleeveScene(50e-6, 0.0, 0.2, -9.81, 1e-4), "", 0.05, 1e-3, {}});
  // Ball dropped from 1 m, e = 0.9: one impact at 0.45 s.
  s.push_back({"ball", "", std::string(source_dir) + "/urdf/ball.urdf", 1.0, 1e-3, {}});
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"nscd_work_precision: error against a converged reference versus wall time"};
  std::string scenes_arg = "pendulum_3d,pendulum_planar,sleeve,ball";
  std::string hs_arg = "1e-3,5e-4,2e-4,1e-4,5e-5,2e-5,1e-5,5e-6,2e-6,1e-6";
  std::string tols_arg = "1e-4,1e-6,1e-8,1e-10";
  std::string csv = "work_precision.csv", source_dir = NSCD_SOURCE_DIR;
  double href = 1e-7, ref_tol = 1e-10;
  int jobs = nscd::sweep::defaultJobs();
  std::vector<std::string> file_scenes, commands;
  double file_duration = 0.2, file_sample_dt = 1e-3;
  std::string adaptive_tols_arg;
  double adaptive_dt = 0, adaptive_solver_tol = 0, ref_adaptive = 0;
  app.add_option("--scenes", scenes_arg, "built-in scenes to run (comma list; 'none' for none)");
  app.add_option("--hs", hs_arg, "time steps (each must divide the sample interval)");
  app.add_option("--tols", tols_arg, "solver tolerances");
  app.add_option("--href", href, "reference time step (default 1e-7)");
  app.add_option("--ref-tol", ref_tol, "reference solver tolerance (default 1e-10)");
  app.add_option("--csv", csv, "output CSV (default work_precision.csv)");
  app.add_option("--jobs", jobs, "worker threads (default: all cores)");
  app.add_option("--scene-file", file_scenes, "extra scene NAME=PATH (e.g. the C-60), repeatable");
  app.add_option("--file-duration", file_duration, "simulated time of the --scene-file scenes");
  app.add_option("--file-sample-dt", file_sample_dt, "comparison grid of the --scene-file scenes (default 1e-3 s)");
  app.add_option("--command", commands, "actuator schedule NAME=t0:v0,... for --scene-file scenes");
  app.add_option("--adaptive-tols", adaptive_tols_arg,
                 "also adaptive runs (step_control=adaptive) at these rtol = atol (comma list)");
  app.add_option("--adaptive-dt", adaptive_dt, "adaptive runs: the largest step (default: the sample interval)");
  app.add_option("--adaptive-solver-tol", adaptive_solver_tol,
                 "adaptive runs: the solver tolerance (default: the tightest of --tols)");
  app.add_option("--ref-adaptive", ref_adaptive,
                 "the reference: an adaptive run at rtol = atol = this (largest step --adaptive-dt), "
                 "solver at --ref-tol, instead of fixed steps of --href");
  CLI11_PARSE(app, argc, argv);

  std::vector<Scene> scenes;
  std::vector<double> hs, tols, adaptive_tols;
  try {
    hs = parseList(hs_arg);
    tols = parseList(tols_arg);
    if (!adaptive_tols_arg.empty()) adaptive_tols = parseList(adaptive_tols_arg);
    std::vector<std::string> wanted;
    if (scenes_arg != "none") {
      std::stringstream ss(scenes_arg);
      for (std::string w; std::getline(ss, w, ',');) wanted.push_back(w);
    }
    for (const Scene& s : builtinScenes(source_dir))
      if (std::find(wanted.begin(), wanted.end(), s.name) != wanted.end()) scenes.push_back(s);
    if (scenes.size() != wanted.size()) throw std::invalid_argument("unknown scene in --scenes " + scenes_arg);
    for (const std::string& c : commands) nscd::parseCommandSchedule(c);  // a bad schedule fails here
    for (const std::string& f : file_scenes) {
      const size_t eq = f.find('=');
      if (eq == std::string::npos) throw std::invalid_argument("--scene-file " + f + ": expected NAME=PATH");
      Scene s{f.substr(0, eq), "", f.substr(eq + 1), file_duration, file_sample_dt, {}};
      s.commands = commands;
      load(s, hs.front(), tols.front());  // fail now, not after the long runs
      scenes.push_back(s);
    }
  } catch (const std::exception& e) {
    std::cerr << "nscd_work_precision: " << e.what() << std::endl;
    return 2;
  }

  std::vector<Job> work;
  const double solver_tol_adaptive =
      adaptive_solver_tol > 0 ? adaptive_solver_tol : *std::min_element(tols.begin(), tols.end());
  for (int s = 0; s < int(scenes.size()); ++s) {
    const double h_max = adaptive_dt > 0 ? adaptive_dt : scenes[s].sample_dt;
    work.push_back({s, ref_adaptive > 0 ? h_max : href, ref_tol, true, ref_adaptive, {}});
    for (double tol : tols)
      for (double h : hs) work.push_back({s, h, tol, false, 0, {}});
    for (double atol : adaptive_tols) work.push_back({s, h_max, solver_tol_adaptive, false, atol, {}});
  }
  // Longest first: the references and the small steps set the total time (an adaptive
  // reference counts as the longest).
  std::vector<size_t> order_idx(work.size());
  for (size_t i = 0; i < work.size(); ++i) order_idx[i] = i;
  auto length = [&](const Job& j) { return j.reference ? INFINITY : scenes[j.scene].duration / j.h; };
  std::stable_sort(order_idx.begin(), order_idx.end(),
                   [&](size_t a, size_t b) { return length(work[a]) > length(work[b]); });
  std::fprintf(stderr, "nscd_work_precision: %zu runs on %d threads\n", work.size(), jobs);
  nscd::sweep::parallelFor(long(work.size()), jobs, [&](long i) {
    Job& j = work[order_idx[i]];
    j.trace = runTrace(scenes[j.scene], j.h, j.tol, j.adaptive_tol);
  });

  std::ofstream out(csv);
  out << "scene,reference,h,tolerance,status,steps,wall_s,us_per_step,iters_mean,unconverged_steps,"
         "pos_err_max,pos_err_rms,force_err_rel,pos_err_end";
  if (!adaptive_tols.empty()) out << ",step_control,step_tol,rejected_steps";
  out << "\n";
  std::map<int, const Trace*> refs;
  for (const Job& j : work)
    if (j.reference) refs[j.scene] = &j.trace;
  for (const Job& j : work) {
    const Errors e = j.reference ? Errors{0, 0, 0, 0} : compare(j.trace, *refs[j.scene]);
    const Trace& t = j.trace;
    out << scenes[j.scene].name << "," << (j.reference ? 1 : 0) << "," << fmt6(j.h) << "," << fmt6(j.tol)
        << "," << t.status << "," << t.steps << "," << fmt6(t.wall_s) << ","
        << fmt6(t.steps ? 1e6 * t.wall_s / t.steps : 0) << "," << fmt6(t.iters_mean) << "," << t.unconverged
        << "," << fmt6(e.pos_max) << "," << fmt6(e.pos_rms) << "," << fmt6(e.force_rel) << "," << fmt6(e.pos_end);
    if (!adaptive_tols.empty())
      out << "," << (j.adaptive_tol > 0 ? "adaptive" : "fixed") << "," << fmt6(j.adaptive_tol) << ","
          << t.rejected;
    out << "\n";
  }
  // Orders at the tightest tolerance.
  const double tight = *std::min_element(tols.begin(), tols.end());
  std::printf("scene,tolerance,order_pos_max,order_pos_rms,order_force,ref_h,ref_wall_s,ref_unconverged%s\n",
              ref_adaptive > 0 ? ",ref_adaptive_tol" : "");
  for (int s = 0; s < int(scenes.size()); ++s) {
    std::vector<double> h, pm, pr, fr;
    for (const Job& j : work)
      if (j.scene == s && !j.reference && j.adaptive_tol == 0 && j.tol == tight) {
        const Errors e = compare(j.trace, *refs[s]);
        h.push_back(j.h), pm.push_back(e.pos_max), pr.push_back(e.pos_rms), fr.push_back(e.force_rel);
      }
    std::printf("%s,%g,%.3f,%.3f,%.3f,%g,%.3f,%ld", scenes[s].name.c_str(), tight, order(h, pm),
                order(h, pr), order(h, fr), ref_adaptive > 0 ? (adaptive_dt > 0 ? adaptive_dt : scenes[s].sample_dt) : href,
                refs[s]->wall_s, refs[s]->unconverged);
    if (ref_adaptive > 0) std::printf(",%g", ref_adaptive);
    std::printf("\n");
  }
  return 0;
}
